#include "quadric_slam/sim/kinect_frames.h"

#include <cmath>

namespace quadric_slam {
namespace {

Eigen::Isometry3d transform(const Eigen::Vector3d& translation, double roll, double pitch,
                            double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = translation;
  return T;
}

}  // namespace

std::vector<FixedTransform> kinectFrameChain() {
  // Offsets of openni_camera's launch files: depth frame 2 cm, RGB frame 4.5 cm to the right
  // (-y) of the camera frame; optical frames rotated rpy(-pi/2, 0, -pi/2).
  const Eigen::Isometry3d optical = transform(Eigen::Vector3d::Zero(), -M_PI / 2, 0.0, -M_PI / 2);
  return {
      {kTumKinectFrame, "/openni_camera", Eigen::Isometry3d::Identity()},
      {"/openni_camera", "/openni_rgb_frame", transform({0.0, -0.045, 0.0}, 0, 0, 0)},
      {"/openni_rgb_frame", kTumRgbOpticalFrame, optical},
      {"/openni_camera", "/openni_depth_frame", transform({0.0, -0.02, 0.0}, 0, 0, 0)},
      {"/openni_depth_frame", "/openni_depth_optical_frame", optical},
  };
}

Eigen::Isometry3d kinectToRgbOptical() {
  const std::vector<FixedTransform> chain = kinectFrameChain();
  return chain[0].T_parent_child * chain[1].T_parent_child * chain[2].T_parent_child;
}

Eigen::Isometry3d worldToKinect(const Eigen::Isometry3d& T_world_optical) {
  return T_world_optical * kinectToRgbOptical().inverse();
}

}  // namespace quadric_slam
