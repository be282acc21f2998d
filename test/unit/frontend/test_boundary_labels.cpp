// completeBoundaryLabels: a wall segment whose rim has depth but no normals gets its rim back, ring
// by ring, while a background surface behind it, points with normals and points out of range stay
// unlabelled; num_points, roi and extent follow.
#include <gtest/gtest.h>

#include <cmath>

#include "quadric_slam/frontend/boundary_labels.h"
#include "quadric_slam/frontend/primitive_shape.h"

namespace qs = quadric_slam;

namespace {

constexpr int kWidth = 40, kHeight = 30;

// A fronto-parallel wall at z = 1 m in columns [10, 30), a background at 3 m elsewhere (0.01 m per
// pixel). Normals only inside columns [14, 26): the rim of 4 columns on each side of the wall has
// none, like the estimator's output next to a depth edge.
pcl::PointCloud<pcl::PointNormal> wallScene() {
  pcl::PointCloud<pcl::PointNormal> cloud(kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      pcl::PointNormal& p = cloud(u, v);
      const bool wall = u >= 10 && u < 30;
      p.z = wall ? 1.0f : 3.0f;
      p.x = 0.01f * (u - 20) * p.z;
      p.y = 0.01f * (v - 15) * p.z;
      const bool with_normal = u >= 14 && u < 26;
      p.normal_x = p.normal_y = with_normal ? 0.f : NAN;
      p.normal_z = with_normal ? -1.f : NAN;
      p.curvature = NAN;
    }
  }
  return cloud;
}

qs::Segmentation wallSegmentation(const pcl::PointCloud<pcl::PointNormal>& cloud) {
  qs::Segmentation segmentation;
  segmentation.labels = cv::Mat::zeros(kHeight, kWidth, CV_16UC1);
  qs::QuadricDetection wall;
  wall.shape = qs::PrimitiveShape::plane(Eigen::Vector3d(0, 0, -1), -1.0);
  wall.label = 1;
  wall.num_points = 0;
  wall.roi = qs::ImageRoi{14, 0, 12, kHeight};
  const Eigen::Isometry3d T_quadric_camera = wall.shape.quadric().pose().inverse();
  wall.extent_min = Eigen::Vector3d::Constant(1e9);
  wall.extent_max = Eigen::Vector3d::Constant(-1e9);
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 14; u < 26; ++u) {
      segmentation.labels.at<std::uint16_t>(v, u) = 1;
      ++wall.num_points;
      const Eigen::Vector3d local = T_quadric_camera * cloud(u, v).getVector3fMap().cast<double>();
      wall.extent_min = wall.extent_min.cwiseMin(local);
      wall.extent_max = wall.extent_max.cwiseMax(local);
    }
  }
  segmentation.detections.push_back(wall);
  return segmentation;
}

}  // namespace

TEST(BoundaryLabels, RimJoinsItsSurfaceRingByRing) {
  const auto cloud = wallScene();
  for (int rings : {0, 1, 3, 6}) {
    SCOPED_TRACE(rings);
    qs::Segmentation segmentation = wallSegmentation(cloud);
    const double extent_before =
        (segmentation.detections[0].extent_max - segmentation.detections[0].extent_min).sum();
    qs::BoundaryCompletion settings;
    settings.rings = rings;
    qs::completeBoundaryLabels(cloud, settings, segmentation);
    // The wall's rim is 4 columns wide on each side; the background is never labelled.
    const int grown = std::min(rings, 4);
    int labelled = 0;
    for (int v = 0; v < kHeight; ++v) {
      for (int u = 0; u < kWidth; ++u) {
        const bool expected = u >= 14 - grown && u < 26 + grown;
        EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, u), expected ? 1 : 0) << u << ", " << v;
        labelled += expected ? 1 : 0;
      }
    }
    const qs::QuadricDetection& wall = segmentation.detections[0];
    EXPECT_EQ(wall.num_points, labelled);
    EXPECT_EQ(wall.roi.x_offset, 14 - grown);
    EXPECT_EQ(wall.roi.width, 12 + 2 * grown);
    EXPECT_EQ(wall.roi.height, kHeight);
    // The box grows by the rim's width (0.01 m per pixel) on both sides.
    EXPECT_NEAR((wall.extent_max - wall.extent_min).sum() - extent_before, 0.02 * grown, 1e-6);
  }
}

TEST(BoundaryLabels, PointsWithNormalsAndOutOfRangeStayUnlabelled) {
  auto cloud = wallScene();
  // Column 13 gets normals (the segmenter judged and refused it); column 12 is too near.
  for (int v = 0; v < kHeight; ++v) {
    cloud(13, v).normal_x = 0.f;
    cloud(13, v).normal_y = 0.f;
    cloud(13, v).normal_z = -1.f;
  }
  qs::Segmentation segmentation = wallSegmentation(cloud);
  qs::BoundaryCompletion settings;
  settings.min_range = 1.5;  // the whole wall is now too near for new labels
  qs::completeBoundaryLabels(cloud, settings, segmentation);
  for (int v = 0; v < kHeight; ++v) {
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 13), 0);
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 27), 0);
  }
  EXPECT_EQ(segmentation.detections[0].num_points, 12 * kHeight);

  // Labels of a size other than the cloud's, or without detections, are left alone.
  qs::Segmentation empty;
  empty.labels = cv::Mat::zeros(3, 3, CV_16UC1);
  qs::completeBoundaryLabels(cloud, qs::BoundaryCompletion(), empty);
  EXPECT_EQ(cv::countNonZero(empty.labels), 0);
}

TEST(BoundaryLabels, FlyingPixelsBeyondTheFitNoiseStayOut) {
  auto cloud = wallScene();
  // Column 13 lies 5 mm behind the wall: inside the segmenter's 8 mm threshold at 1 m, but beyond
  // 3 x the fit's 1 mm RMS, like the mixed depths at a depth edge.
  for (int v = 0; v < kHeight; ++v)
    cloud(13, v).z += 0.005f;
  qs::Segmentation segmentation = wallSegmentation(cloud);
  segmentation.detections[0].fit_rms = 0.001;
  qs::completeBoundaryLabels(cloud, qs::BoundaryCompletion(), segmentation);
  for (int v = 0; v < kHeight; ++v) {
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 13), 0);
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 12), 0) << "not reached past column 13";
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 26), 1);
  }
  segmentation = wallSegmentation(cloud);
  segmentation.detections[0].fit_rms = 0.002;  // noisier fit: 6 mm gate
  qs::completeBoundaryLabels(cloud, qs::BoundaryCompletion(), segmentation);
  for (int v = 0; v < kHeight; ++v)
    EXPECT_EQ(segmentation.labels.at<std::uint16_t>(v, 13), 1);
}
