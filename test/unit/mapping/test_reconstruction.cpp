// QuadricReconstruction: noisy points of known surfaces, seen from known camera poses, come back on
// the surfaces in the map frame, one per voxel; they follow a landmark whose estimate moves;
// outliers, NaNs and points beyond the per-landmark cap are not stored.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/mapping/reconstruction.h"

namespace qs = quadric_slam;

namespace {

Eigen::Isometry3d cameraPose() {
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  T_map_camera.linear() =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, 1.0, -0.3).normalized()).toRotationMatrix();
  T_map_camera.translation() = Eigen::Vector3d(0.5, -1.0, 1.2);
  return T_map_camera;
}

// Points on a cylinder (axis through `point` along `axis`, radius r) over an arc and a length, with
// Gaussian noise along the radius, in the camera frame of T_map_camera.
std::vector<Eigen::Vector3f> cylinderPointsInCamera(const qs::CylinderShape& cylinder,
                                                    const Eigen::Isometry3d& T_map_camera,
                                                    double noise, int count, unsigned seed) {
  const Eigen::Matrix3d R = qs::rotationWithAxis(cylinder.axis, 2);
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> angle(0.0, M_PI), along(-0.2, 0.2);
  std::normal_distribution<double> radial(0.0, noise);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < count; ++i) {
    const double a = angle(random), r = cylinder.radius + radial(random);
    const Eigen::Vector3d p_map =
        cylinder.point + R * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), along(random));
    points.push_back((T_map_camera.inverse() * p_map).cast<float>());
  }
  return points;
}

}  // namespace

TEST(QuadricReconstruction, NoisyPointsComeBackOnTheSurfaceOnePerVoxel) {
  qs::CylinderShape shape;
  shape.point = Eigen::Vector3d(1.0, 0.5, 0.3);
  shape.axis = Eigen::Vector3d(0.1, 0.2, 1.0);
  shape.radius = 0.15;
  const qs::QuadricModel cylinder = qs::quadricFromShape(shape);
  const Eigen::Isometry3d T_map_camera = cameraPose();
  const auto points = cylinderPointsInCamera(shape, T_map_camera, 0.003, 20000, 1);

  qs::QuadricReconstruction::Params params;
  params.voxel_size = 0.01;
  qs::QuadricReconstruction reconstruction(params);
  const int added = reconstruction.addPoints(7, cylinder, T_map_camera, points);
  // Half a cylinder of radius 0.15 m and length 0.4 m: ~0.19 m^2, a few thousand 1 cm voxels (the
  // 3 mm radial noise spreads points over a second layer in places).
  EXPECT_GT(added, 1500);
  EXPECT_LT(added, 6000);
  EXPECT_EQ(reconstruction.size(), static_cast<std::size_t>(added));
  EXPECT_EQ(reconstruction.size(7), static_cast<std::size_t>(added));
  EXPECT_EQ(reconstruction.size(8), 0u);

  const auto cloud = reconstruction.cloud({{7, cylinder}});
  ASSERT_EQ(cloud.size(), static_cast<std::size_t>(added));
  for (const auto& p : cloud) {
    const Eigen::Vector3d point(p.x, p.y, p.z);
    EXPECT_LT(qs::exactDistance(cylinder, point), 1e-6);
    EXPECT_EQ(p.label, 7u);
    // On the observed half, within the observed length.
    const Eigen::Vector3d from_axis = point - shape.point;
    EXPECT_LT(std::abs(from_axis.dot(shape.axis.normalized())), 0.2 + 1e-3);
  }

  // The same points again: every voxel is taken.
  EXPECT_EQ(reconstruction.addPoints(7, cylinder, T_map_camera, points), 0);
}

TEST(QuadricReconstruction, PointsFollowTheLandmarkEstimate) {
  qs::SphereShape shape;
  shape.center = Eigen::Vector3d(0.2, 0.1, 2.0);
  shape.radius = 0.2;
  const qs::QuadricModel sphere = qs::quadricFromShape(shape);
  const Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 200; ++i) {
    const double a = 0.02 * i, b = 0.5 + 0.005 * i;
    points.push_back(
        (shape.center + shape.radius * Eigen::Vector3d(std::cos(a) * std::sin(b),
                                                       std::sin(a) * std::sin(b), -std::cos(b)))
            .cast<float>());
  }
  qs::QuadricReconstruction reconstruction;
  ASSERT_GT(reconstruction.addPoints(3, sphere, T_map_camera, points), 50);

  // The optimiser moves the sphere by 10 cm and grows it by 1 cm: the points move with it.
  qs::SphereShape moved = shape;
  moved.center += Eigen::Vector3d(0.1, 0.0, 0.0);
  moved.radius = 0.21;
  const qs::QuadricModel moved_sphere = qs::quadricFromShape(moved);
  const auto cloud = reconstruction.cloud({{3, moved_sphere}});
  ASSERT_EQ(cloud.size(), reconstruction.size(3));
  for (const auto& p : cloud) {
    const Eigen::Vector3d point(p.x, p.y, p.z);
    EXPECT_NEAR((point - moved.center).norm(), 0.21, 1e-6);
    // Same direction from the centre as one of the points added.
    const Eigen::Vector3d on_original =
        shape.center + shape.radius * (point - moved.center).normalized();
    double nearest = 1e9;
    for (const Eigen::Vector3f& original : points)
      nearest = std::min(nearest, (original.cast<double>() - on_original).norm());
    EXPECT_LT(nearest, 1e-5);
  }
  // Landmarks not asked for, or removed, are not drawn.
  EXPECT_TRUE(reconstruction.cloud({{4, moved_sphere}}).empty());
  reconstruction.removeLandmark(3);
  EXPECT_EQ(reconstruction.size(), 0u);
  EXPECT_TRUE(reconstruction.cloud({{3, moved_sphere}}).empty());
}

TEST(QuadricReconstruction, OutliersNaNsAndTheCapAreRespected) {
  qs::PlaneShape shape;
  shape.normal = Eigen::Vector3d(0, 0, 1);
  shape.offset = 0.0;
  const qs::QuadricModel floor = qs::quadricFromShape(shape);
  const Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 100; ++i)
    points.emplace_back(0.02f * i, 0.f, 0.001f);  // on the floor, 2 cm apart
  points.emplace_back(0.5f, 0.5f, 0.3f);          // a box on the floor: 30 cm off the surface
  points.emplace_back(NAN, 0.f, 0.f);
  points.emplace_back(0.f, INFINITY, 0.f);

  qs::QuadricReconstruction reconstruction;
  EXPECT_EQ(reconstruction.addPoints(1, floor, T_map_camera, points), 100);
  for (const auto& p : reconstruction.cloud({{1, floor}}))
    EXPECT_NEAR(p.z, 0.f, 1e-6f);

  qs::QuadricReconstruction::Params capped;
  capped.max_points_per_landmark = 10;
  qs::QuadricReconstruction small(capped);
  EXPECT_EQ(small.addPoints(1, floor, T_map_camera, points), 10);
  EXPECT_EQ(small.addPoints(1, floor, T_map_camera, points), 0);
  EXPECT_EQ(small.addPoints(2, floor, T_map_camera, {{NAN, 0.f, 0.f}}), 0);
  EXPECT_EQ(small.size(2), 0u);
  small.clear();
  EXPECT_EQ(small.size(), 0u);
}

TEST(QuadricReconstruction, ParamsValidateNamesTheField) {
  qs::QuadricReconstruction::Params params;
  params.voxel_size = 0.0;
  try {
    qs::QuadricReconstruction reconstruction(params);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("voxel_size"), std::string::npos);
  }
  params = {};
  params.max_points_per_landmark = 0;
  EXPECT_THROW(params.validate(), std::invalid_argument);
  params = {};
  params.max_surface_distance = -1.0;
  EXPECT_THROW(params.validate(), std::invalid_argument);
}

// Colours travel with their points: each stored point keeps the colour of the point that filled its
// voxel, a landmark added without colours has uncoloured points (alpha 0: its own colour is the
// caller's), and a colour list that does not match the points is refused.
TEST(QuadricReconstruction, PointsKeepTheirColoursAndUncolouredLandmarksStayUncoloured) {
  qs::CylinderShape shape;
  shape.point = Eigen::Vector3d(1.0, 0.5, 0.3);
  shape.axis = Eigen::Vector3d(0.0, 0.0, 1.0);
  shape.radius = 0.2;
  const qs::QuadricModel cylinder = qs::quadricFromShape(shape);
  const Eigen::Isometry3d T_map_camera = cameraPose();
  const auto points = cylinderPointsInCamera(shape, T_map_camera, 0.0, 4000, 2);
  // The colour pattern: red grows with the height along the axis, blue is fixed.
  std::vector<std::uint32_t> colours;
  for (const Eigen::Vector3f& p : points) {
    const double height = (T_map_camera * p.cast<double>()).z() - shape.point.z();  // [-0.2, 0.2]
    const auto red = static_cast<std::uint32_t>(std::lround((height + 0.2) / 0.4 * 255.0));
    colours.push_back(0xFF000000u | red << 16 | 0x40u);
  }
  qs::QuadricReconstruction reconstruction;
  EXPECT_THROW(reconstruction.addPoints(1, cylinder, T_map_camera, points, {0xFF000000u}),
               std::invalid_argument);
  const int added = reconstruction.addPoints(1, cylinder, T_map_camera, points, colours);
  ASSERT_GT(added, 500);
  qs::CylinderShape other = shape;
  other.point.x() += 2.0;
  const qs::QuadricModel uncoloured = qs::quadricFromShape(other);
  ASSERT_GT(reconstruction.addPoints(2, uncoloured, T_map_camera,
                                     cylinderPointsInCamera(other, T_map_camera, 0.0, 1000, 3)),
            100);

  int coloured_points = 0, plain_points = 0;
  for (const auto& p : reconstruction.cloud({{1, cylinder}, {2, uncoloured}})) {
    if (p.label == 2u) {
      EXPECT_EQ(p.rgba, 0u);
      ++plain_points;
      continue;
    }
    ++coloured_points;
    EXPECT_EQ(p.rgba >> 24, 0xFFu);
    EXPECT_EQ(p.rgba & 0xFFu, 0x40u);
    // Within a voxel (1 cm of 40 cm height: 255 / 40 per cm) of the pattern at the stored point.
    const double red_expected = (p.z - shape.point.z() + 0.2) / 0.4 * 255.0;
    EXPECT_NEAR(static_cast<double>((p.rgba >> 16) & 0xFFu), red_expected, 0.5 + 255.0 / 40.0);
  }
  EXPECT_EQ(coloured_points, added);
  EXPECT_GT(plain_points, 100);
}
