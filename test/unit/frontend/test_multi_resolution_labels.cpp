// upsample (frontend/multi_resolution_labels.h): the full-resolution pixels of a wall take the
// label of the coarse samples around them, except those flagged as taken by other segments; the
// support counts the labelled pixels only.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "quadric_slam/frontend/multi_resolution_labels.h"
#include "quadric_slam/frontend/primitive_shape.h"

namespace qs = quadric_slam;

namespace {

constexpr int kWidth = 40, kHeight = 30, kDecimation = 2;

// A fronto-parallel wall at z = 1 m filling the image (0.01 m per pixel), normals towards the
// camera.
pcl::PointCloud<pcl::PointNormal> wall() {
  pcl::PointCloud<pcl::PointNormal> cloud(kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      pcl::PointNormal& p = cloud(u, v);
      p.z = 1.0f;
      p.x = 0.01f * (u - 20);
      p.y = 0.01f * (v - 15);
      p.normal_x = p.normal_y = 0.f;
      p.normal_z = -1.f;
    }
  }
  return cloud;
}

// The wall as one plane detection labelling every sample of the grid decimated by kDecimation.
qs::Segmentation coarseWall() {
  qs::Segmentation coarse;
  coarse.labels = cv::Mat::ones(kHeight / kDecimation, kWidth / kDecimation, CV_16UC1);
  qs::QuadricDetection detection;
  detection.shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -1.0);
  detection.label = 1;
  detection.num_points = coarse.labels.rows * coarse.labels.cols;
  detection.fit_rms = 0.001;
  detection.covariance = Eigen::MatrixXd::Identity(3, 3) * 1e-6;
  coarse.detections.push_back(detection);
  return coarse;
}

}  // namespace

TEST(MultiResolutionLabels, EveryPixelOfTheWallTakesItsLabel) {
  const auto cloud = wall();
  const qs::Segmentation full =
      qs::upsample(cloud, coarseWall(), kDecimation, qs::QuadricSegmenter::Params());
  ASSERT_EQ(full.detections.size(), 1u);
  EXPECT_EQ(cv::countNonZero(full.labels == 1), kWidth * kHeight);
  EXPECT_EQ(full.detections[0].num_points, kWidth * kHeight);
}

TEST(MultiResolutionLabels, TakenPixelsStayUnlabelled) {
  const auto cloud = wall();
  std::vector<std::uint8_t> taken(cloud.size(), 0);
  for (int v = 5; v < 12; ++v)
    for (int u = 8; u < 20; ++u)
      taken[v * kWidth + u] = 1;
  const qs::Segmentation full =
      qs::upsample(cloud, coarseWall(), kDecimation, qs::QuadricSegmenter::Params(), taken);
  ASSERT_EQ(full.detections.size(), 1u);
  for (int v = 0; v < kHeight; ++v)
    for (int u = 0; u < kWidth; ++u)
      EXPECT_EQ(full.labels.at<std::uint16_t>(v, u), taken[v * kWidth + u] ? 0 : 1)
          << u << ", " << v;
  EXPECT_EQ(full.detections[0].num_points, kWidth * kHeight - 7 * 12);
}

TEST(MultiResolutionLabels, TakenFlagsMustCoverTheCloud) {
  EXPECT_THROW(qs::upsample(wall(), coarseWall(), kDecimation, qs::QuadricSegmenter::Params(),
                            std::vector<std::uint8_t>(10, 0)),
               std::invalid_argument);
}
