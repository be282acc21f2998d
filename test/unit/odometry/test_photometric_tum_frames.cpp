// The photometric refinement (odometry/photometric_refinement.h) on real Kinect frames: two
// fr1_xyz frames of the TUM RGB-D benchmark (depth registered to colour, 0.1 s apart) with the
// depth cut down to the desk top, the one plane the segmenter finds largest in each. A plane fixes
// three directions (its distance and two tilts); the motion along it, here most of the real 2.6 cm,
// is left to the intensities of what lies on the desk (papers, a keyboard's print, books). The
// answer is checked against motion capture. Real colour differs from a rendering in every way the
// method must survive: sensor noise, auto exposure, a rolling shutter, colour taken 12-15 ms after
// the depth, and a registration of depth to colour good to a pixel or two.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>

#include "quadric_slam/frontend/normal_estimator.h"
#include "quadric_slam/frontend/quadric_segmenter.h"
#include "quadric_slam/io/depth_png.h"
#include "quadric_slam/io/frame_source.h"
#include "quadric_slam/odometry/odometry_tracker.h"
#include "tum_fr1_xyz_pair.h"

namespace quadric_slam {
namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;

// The frame's cloud, every point off its largest plane segment made invalid and every point on it
// given the segment's normal (as the shipped odometry does, surface_normals: true).
Cloud largestPlaneOnly(const std::string& depth_png, const CameraIntrinsics& k,
                       Eigen::Vector3d* normal) {
  const cv::Mat depth_m = readTumDepthPng(test::shippedData(depth_png).string());
  const Cloud cloud = NormalEstimator(NormalEstimator::Params())
                          .compute(backProject(depthViewOf(depth_m), k, BackProjectionParams()));
  const Segmentation segmentation = QuadricSegmenter(QuadricSegmenter::Params()).segment(cloud);
  const QuadricDetection* largest = nullptr;
  for (const QuadricDetection& d : segmentation.detections)
    if (d.shape.quadric_class == QuadricClass::kPlane &&
        (!largest || d.num_points > largest->num_points))
      largest = &d;
  Cloud plane = cloud;
  if (!largest)
    return Cloud();
  *normal = largest->shape.direction;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < static_cast<int>(cloud.height); ++y)
    for (int x = 0; x < static_cast<int>(cloud.width); ++x) {
      pcl::PointNormal& p = plane.at(x, y);
      if (segmentation.labels.at<std::uint16_t>(y, x) != largest->label) {
        p.x = p.y = p.z = p.normal_x = p.normal_y = p.normal_z = nan;
      } else {
        p.getNormalVector3fMap() = normal->cast<float>();
      }
    }
  return plane;
}

struct PairResult {
  OdometryTracker::Result second;
  Eigen::Isometry3d truth;
  Eigen::Vector3d plane_normal;  // the desk top's, in the first frame
};

PairResult trackDeskTopPair(bool photometric) {
  const CameraIntrinsics k = test::fr1Intrinsics();
  Eigen::Vector3d normal_a, normal_b;
  const Cloud a = largestPlaneOnly(test::kFr1XyzDepthA, k, &normal_a);
  const Cloud b = largestPlaneOnly(test::kFr1XyzDepthB, k, &normal_b);
  EXPECT_FALSE(a.empty() || b.empty()) << "no plane segment in the fr1_xyz frames";
  const cv::Mat rgb_a = readRgbPng(test::shippedData(test::kFr1XyzRgbA).string());
  const cv::Mat rgb_b = readRgbPng(test::shippedData(test::kFr1XyzRgbB).string());

  PairResult out;
  out.plane_normal = normal_a;
  EXPECT_TRUE(
      test::fr1XyzTrueMotion(test::kFr1XyzDepthStampA, test::kFr1XyzDepthStampB, &out.truth));
  // The same surface in both frames: the normals agree once the true rotation is applied.
  EXPECT_GT((out.truth.linear() * normal_b).dot(normal_a), std::cos(5.0 * M_PI / 180));

  OdometryTracker::Params params;
  params.photometric_refinement = photometric;
  OdometryTracker tracker(params);
  tracker.track(a, k, test::kFr1XyzDepthStampA, nullptr, &rgb_a);
  out.second = tracker.track(b, k, test::kFr1XyzDepthStampB, nullptr, &rgb_b);
  return out;
}

double translationError(const PairResult& r) {
  return (r.truth.inverse() * r.second.T_odom_camera).translation().norm();
}

TEST(PhotometricOnTumFrames, ADeskTopAloneLeavesTheMotionAlongItToTheIntensities) {
  const PairResult depth_only = trackDeskTopPair(false);
  const PairResult refined = trackDeskTopPair(true);
  // The desk top alone cannot measure the motion along it: depth only keeps the start there.
  ASSERT_EQ(depth_only.second.status, TrackingStatus::kDegenerate) << depth_only.second.icp.message;
  const Eigen::Vector3d n = depth_only.plane_normal;
  const Eigen::Vector3d true_step = depth_only.truth.translation();
  const double along_desk = (true_step - n * n.dot(true_step)).norm();
  ASSERT_GT(along_desk, 0.01) << "the true motion along the desk is under 1 cm";
  const double depth_error = translationError(depth_only);
  EXPECT_GT(depth_error, 0.5 * along_desk);
  EXPECT_EQ(depth_only.second.icp.constrained_dof, 3);

  ASSERT_TRUE(refined.second.photometric.refined) << refined.second.photometric.message;
  const double refined_error = translationError(refined);
  const double refined_rotation =
      pose_math::rotationAngle(refined.truth.inverse() * refined.second.T_odom_camera);
  // Motion capture's own relative rotation here is uncertain by a few tenths of a degree
  // (test_icp_tum_frames: ICP over the whole frame is 0.7 degrees off it).
  EXPECT_LT(refined_error, 0.006) << "depth only " << depth_error;
  EXPECT_LT(refined_error, 0.3 * depth_error);
  EXPECT_LT(refined_rotation, 0.6 * M_PI / 180);
  EXPECT_LT(refined.second.photometric.rms_after, refined.second.photometric.rms_before);
  // A refined step stays degenerate: the intensities are not the trusted geometry.
  EXPECT_EQ(refined.second.status, TrackingStatus::kDegenerate);
  RecordProperty("depth_only_error_mm", static_cast<int>(depth_error * 1000));
  RecordProperty("refined_error_mm", static_cast<int>(refined_error * 1000));
  std::printf(
      "desk top only: depth %.1f mm, refined %.1f mm / %.2f deg off motion capture "
      "(true motion %.1f mm, %.1f mm of it along the desk), %d pixels, intensity RMS "
      "%.1f -> %.1f, depth constrains %d directions\n",
      depth_error * 1000, refined_error * 1000, refined_rotation * 180 / M_PI,
      true_step.norm() * 1000, along_desk * 1000, refined.second.photometric.points,
      refined.second.photometric.rms_before, refined.second.photometric.rms_after,
      depth_only.second.icp.constrained_dof);
}

}  // namespace
}  // namespace quadric_slam
