// The fixed frame chain of a Kinect in the TUM RGB-D bags: /kinect -> /openni_camera ->
// /openni_rgb_frame -> /openni_rgb_optical_frame and /openni_camera -> /openni_depth_frame ->
// /openni_depth_optical_frame. Body frames are x forward, z up; optical frames x right, y down,
// z forward (rotation rpy(-pi/2, 0, -pi/2) from the body frame).
#pragma once

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace quadric_slam {

struct FixedTransform {
  std::string parent, child;  // tf frame ids as in the TUM bags (leading '/')
  Eigen::Isometry3d T_parent_child = Eigen::Isometry3d::Identity();
};

constexpr const char* kTumWorldFrame = "/world";
constexpr const char* kTumKinectFrame = "/kinect";
constexpr const char* kTumRgbOpticalFrame = "/openni_rgb_optical_frame";

// The five fixed transforms, parents before children.
std::vector<FixedTransform> kinectFrameChain();
// Composition of the chain from /kinect to /openni_rgb_optical_frame.
Eigen::Isometry3d kinectToRgbOptical();
// The /world -> /kinect transform that puts the RGB optical frame at T_world_optical:
// T_world_kinect = T_world_optical * kinectToRgbOptical()^-1.
Eigen::Isometry3d worldToKinect(const Eigen::Isometry3d& T_world_optical);

}  // namespace quadric_slam
