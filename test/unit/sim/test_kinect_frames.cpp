#include <gtest/gtest.h>

#include <cmath>

#include "quadric_slam/sim/kinect_frames.h"

using namespace quadric_slam;

TEST(KinectFrames, ChainIsTheTumTree) {
  const std::vector<FixedTransform> chain = kinectFrameChain();
  ASSERT_EQ(chain.size(), 5u);
  EXPECT_EQ(chain[0].parent, "/kinect");
  EXPECT_EQ(chain[0].child, "/openni_camera");
  EXPECT_EQ(chain[2].child, "/openni_rgb_optical_frame");
  EXPECT_EQ(chain[4].parent, "/openni_depth_frame");
  EXPECT_EQ(chain[4].child, "/openni_depth_optical_frame");
}

TEST(KinectFrames, OpticalFrameLooksAlongTheBodyXAxis) {
  // Body frames x forward, z up; optical z forward, x right (= body -y), y down (= body -z).
  const Eigen::Matrix3d R = kinectToRgbOptical().linear();
  EXPECT_NEAR((R.col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((R.col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((R.col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 0, 1e-12);
}

TEST(KinectFrames, WorldToKinectComposesBackToTheOpticalPose) {
  Eigen::Isometry3d T_world_optical = Eigen::Isometry3d::Identity();
  T_world_optical.linear() =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).matrix();
  T_world_optical.translation() = Eigen::Vector3d(1.2, -0.3, 1.5);
  const Eigen::Isometry3d T_world_kinect = worldToKinect(T_world_optical);
  const std::vector<FixedTransform> c = kinectFrameChain();
  const Eigen::Isometry3d composed =
      T_world_kinect * c[0].T_parent_child * c[1].T_parent_child * c[2].T_parent_child;
  EXPECT_TRUE(composed.isApprox(T_world_optical, 1e-12));
}
