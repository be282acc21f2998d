#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/odometry/surface_normals.h"

namespace quadric_slam {
namespace {

constexpr int kWidth = 64, kHeight = 48;
constexpr double kFocal = 50.0;

// An organized cloud seeing a plane z = depth (normal towards the camera: -z), each normal
// tilted by random noise as a normal estimator's window gives it far away.
pcl::PointCloud<pcl::PointNormal> noisyWall(double depth, double tilt_sigma, std::mt19937& rng) {
  pcl::PointCloud<pcl::PointNormal> cloud(kWidth, kHeight);
  std::normal_distribution<float> tilt(0.0f, static_cast<float>(tilt_sigma));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      pcl::PointNormal& p = cloud.at(u, v);
      p.x = static_cast<float>((u - kWidth / 2) / kFocal * depth);
      p.y = static_cast<float>((v - kHeight / 2) / kFocal * depth);
      p.z = static_cast<float>(depth);
      const Eigen::Vector3f n = Eigen::Vector3f(tilt(rng), tilt(rng), -1.0f).normalized();
      p.normal_x = n.x();
      p.normal_y = n.y();
      p.normal_z = n.z();
    }
  }
  return cloud;
}

QuadricMeasurement planeObservation(const Eigen::Vector3d& normal, double offset, double fit_rms,
                                    const ImageRoi& roi) {
  QuadricMeasurement m;
  m.quadric_camera = quadricFromShape(PlaneShape{normal.normalized(), offset});
  m.fit_rms = fit_rms;
  m.image_roi = roi;
  return m;
}

double angleToMinusZ(const pcl::PointNormal& p) {
  return std::acos(std::clamp(
      -p.normal_z / Eigen::Vector3f(p.normal_x, p.normal_y, p.normal_z).norm(), -1.0f, 1.0f));
}

TEST(SurfaceNormals, PointsOnAnObservedPlaneTakeItsNormalInsideItsBoxOnly) {
  std::mt19937 rng(3);
  pcl::PointCloud<pcl::PointNormal> cloud = noisyWall(3.0, 0.25, rng);
  // The wall z = 3 observed with its normal pointing away from the camera (the sign is not the
  // observation's to give), over the left half of the image.
  const ImageRoi left{0, 0, kWidth / 2, kHeight};
  const std::vector<QuadricMeasurement> observations{
      planeObservation(Eigen::Vector3d::UnitZ(), 3.0, 0.01, left)};
  SurfaceNormalParams params;
  const int replaced = adoptSurfaceNormals(observations, params, 1, cloud);
  // Normals tilted by more than 45 degrees stay (they might be another surface's).
  int kept_tilted = 0, left_points = 0;
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const double angle = angleToMinusZ(cloud.at(u, v));
      if (u < kWidth / 2) {
        ++left_points;
        if (angle > 1e-6) {
          EXPECT_GT(angle, params.max_angle);
          ++kept_tilted;
        }
      } else if (u > kWidth / 2 + 1) {
        EXPECT_GT(angle, 1e-4) << "outside the box, at " << u << ", " << v;
      }
    }
  }
  EXPECT_EQ(replaced, left_points - kept_tilted);
  EXPECT_GT(replaced, left_points * 9 / 10);
}

TEST(SurfaceNormals, PointsOffTheSurfaceOrNearerThanTheMinimumDepthKeepTheirNormals) {
  std::mt19937 rng(4);
  const ImageRoi all{0, 0, kWidth, kHeight};
  SurfaceNormalParams params;
  params.min_max_distance = 0.01;
  // The plane observed 5 cm behind the points, with a 1 cm fit: no point is on it.
  pcl::PointCloud<pcl::PointNormal> cloud = noisyWall(3.0, 0.1, rng);
  EXPECT_EQ(adoptSurfaceNormals({planeObservation(Eigen::Vector3d::UnitZ(), 3.05, 0.01, all)},
                                params, 1, cloud),
            0);
  // Within three times a 2 cm fit RMS: all of them.
  EXPECT_EQ(adoptSurfaceNormals({planeObservation(Eigen::Vector3d::UnitZ(), 3.05, 0.02, all)},
                                params, 1, cloud),
            kWidth * kHeight - 0);
  // Nearer than min_depth: none.
  cloud = noisyWall(1.2, 0.1, rng);
  params.min_depth = 1.5;
  EXPECT_EQ(adoptSurfaceNormals({planeObservation(Eigen::Vector3d::UnitZ(), 1.2, 0.01, all)},
                                params, 1, cloud),
            0);
  params.enabled = false;
  params.min_depth = 0;
  EXPECT_EQ(adoptSurfaceNormals({planeObservation(Eigen::Vector3d::UnitZ(), 1.2, 0.01, all)},
                                params, 1, cloud),
            0);
}

TEST(SurfaceNormals, TheNearerOfTwoSurfacesWinsAndOnlyTheStrideGridIsTouched) {
  std::mt19937 rng(5);
  pcl::PointCloud<pcl::PointNormal> cloud = noisyWall(3.0, 0.05, rng);
  const ImageRoi all{0, 0, kWidth, kHeight};
  // A plane tilted by 10 degrees through the image centre's point, and the true wall 8 mm off:
  // both accept every point near the centre, the wall is nearer there.
  const Eigen::Vector3d tilted(std::sin(0.1745), 0, std::cos(0.1745));
  const std::vector<QuadricMeasurement> observations{
      planeObservation(tilted, tilted.dot(Eigen::Vector3d(0, 0, 3.0)), 0.02, all),
      planeObservation(Eigen::Vector3d::UnitZ(), 3.008, 0.02, all)};
  const int stride = 2;
  const int replaced = adoptSurfaceNormals(observations, SurfaceNormalParams{}, stride, cloud);
  EXPECT_EQ(replaced, (kWidth / stride) * (kHeight / stride));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const pcl::PointNormal& p = cloud.at(u, v);
      if (u % stride != 0 || v % stride != 0) {
        EXPECT_GT(angleToMinusZ(p), 1e-6);  // untouched
        continue;
      }
      // The wall's normal where it is the nearer, the tilted plane's where that is (|x| large
      // enough that the tilted plane passes within 8 mm of the wall's points).
      const double to_tilted = std::abs(tilted.dot(Eigen::Vector3d(p.x, p.y, p.z)) -
                                        tilted.dot(Eigen::Vector3d(0, 0, 3.0)));
      const double expected_angle = to_tilted < 0.008 ? 0.1745 : 0.0;
      EXPECT_NEAR(angleToMinusZ(p), expected_angle, 1e-5) << u << ", " << v;
    }
  }
}

// The scratch buffers carried from a frame with a surface everywhere to one with a surface in one
// corner hold nothing over: each call gives what a call without them gives.
TEST(SurfaceNormals, ReusedScratchGivesTheSameNormalsAsFreshBuffers) {
  std::mt19937 rng(9);
  const pcl::PointCloud<pcl::PointNormal> wall = noisyWall(3.0, 0.05, rng);
  const std::vector<QuadricMeasurement> everywhere{
      planeObservation(Eigen::Vector3d::UnitZ(), 3.0, 0.02, ImageRoi{0, 0, kWidth, kHeight})};
  const std::vector<QuadricMeasurement> corner{planeObservation(
      Eigen::Vector3d::UnitZ(), 3.0, 0.02, ImageRoi{0, 0, kWidth / 4, kHeight / 4})};
  SurfaceNormalScratch scratch;
  for (const auto* observations : {&everywhere, &corner}) {
    pcl::PointCloud<pcl::PointNormal> fresh = wall, reused = wall;
    const int fresh_count = adoptSurfaceNormals(*observations, SurfaceNormalParams{}, 2, fresh);
    EXPECT_EQ(adoptSurfaceNormals(*observations, SurfaceNormalParams{}, 2, reused, &scratch),
              fresh_count);
    EXPECT_GT(fresh_count, 0);
    for (std::size_t i = 0; i < wall.size(); ++i)
      EXPECT_EQ(angleToMinusZ(fresh.points[i]), angleToMinusZ(reused.points[i])) << i;
  }
}

TEST(SurfaceNormals, InvalidParametersAndStrideAreRefused) {
  SurfaceNormalParams params;
  params.max_angle = 0;
  EXPECT_THROW(params.validate(), std::invalid_argument);
  params = SurfaceNormalParams{};
  params.max_distance_rms = -1;
  EXPECT_THROW(params.validate(), std::invalid_argument);
  pcl::PointCloud<pcl::PointNormal> cloud(4, 4);
  EXPECT_THROW(adoptSurfaceNormals({}, SurfaceNormalParams{}, 0, cloud), std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
