// Point-to-plane ICP on real Kinect frames of the TUM RGB-D benchmark (fr1_xyz), checked against
// the benchmark's motion-capture ground truth (frames and a ground-truth excerpt in test/data).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <string>

#include "quadric_slam/frontend/frame.h"
#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/odometry/point_to_plane_icp.h"
#include "tum_fr1_xyz_pair.h"

namespace quadric_slam {
namespace {

pcl::PointCloud<pcl::PointNormal>::Ptr loadDepth(const std::string& path,
                                                 const CameraIntrinsics& k) {
  const cv::Mat depth = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (depth.empty() || depth.type() != CV_16UC1)
    return nullptr;
  DepthImageView<std::uint16_t> view;
  view.data = depth.data;
  view.width = depth.cols;
  view.height = depth.rows;
  view.row_step_bytes = depth.step;
  view.metres_per_unit = 1.0 / 5000.0;  // TUM PNG depth
  const pcl::PointCloud<pcl::PointXYZ> xyz = backProject(view, k, BackProjectionParams());
  return pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>(
      NormalEstimator(NormalEstimator::Params()).compute(xyz));
}

// Two fr1_xyz depth frames 0.1 s apart (2.6 cm and 2 degrees of real hand-held motion). The
// estimate must agree with motion capture to 5 mm and 1 degree. Why not tighter: the benchmark's
// own RGB-D SLAM reaches 1.3 cm ATE on this sequence; mocap positions are good to about 1 mm, but
// the relative rotation read from the ground truth changes by 0.25 degrees per 10 ms sample around
// these stamps (1.5-2.5 degrees for bracketing samples within +-20 ms), so a few milliseconds of
// depth/mocap clock offset move the reference by several tenths of a degree. (The benchmark's
// RGB-D SLAM trajectory gives 1.61 degrees for this pair, ICP 1.56, the interpolated truth 2.05.)
TEST(IcpOnTumFrames, Fr1XyzMatchesMotionCapture) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  auto a = loadDepth(test::shippedData(test::kFr1XyzDepthA).string(), k);
  auto b = loadDepth(test::shippedData(test::kFr1XyzDepthB).string(), k);
  ASSERT_TRUE(a && b) << "TUM fr1_xyz depth frames not readable in test/data";
  Eigen::Isometry3d T_a_b;
  ASSERT_TRUE(test::fr1XyzTrueMotion(test::kFr1XyzDepthStampA, test::kFr1XyzDepthStampB, &T_a_b))
      << "no ground truth around the frames' stamps in " << test::kFr1XyzGroundTruth;
  ASSERT_GT(T_a_b.translation().norm(), 0.02);  // the frames really are apart

  PointToPlaneIcp icp(PointToPlaneIcp::Params{});
  icp.setReference(*a, k);
  const PointToPlaneIcp::Result r = icp.align(*b, Eigen::Isometry3d::Identity());
  ASSERT_EQ(r.status, TrackingStatus::kOk) << r.message;
  const Eigen::Isometry3d error = T_a_b.inverse() * r.T_reference_current;
  EXPECT_LT(error.translation().norm(), 5e-3)
      << "estimate " << r.T_reference_current.translation().transpose() << " truth "
      << T_a_b.translation().transpose();
  EXPECT_LT(pose_math::rotationAngle(error), 1.0 * M_PI / 180)
      << "estimate " << Eigen::AngleAxisd(r.T_reference_current.linear()).angle() * 180 / M_PI
      << " deg about " << Eigen::AngleAxisd(r.T_reference_current.linear()).axis().transpose()
      << ", truth " << Eigen::AngleAxisd(T_a_b.linear()).angle() * 180 / M_PI << " deg about "
      << Eigen::AngleAxisd(T_a_b.linear()).axis().transpose() << "; translation error "
      << error.translation().norm();
  EXPECT_GT(r.inlier_fraction, 0.7);
}

}  // namespace
}  // namespace quadric_slam
