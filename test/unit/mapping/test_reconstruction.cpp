// QuadricReconstruction: noisy points of known surfaces, seen from known camera poses, come back on
// the surfaces in the map frame, one per voxel; they follow a landmark whose estimate moves;
// outliers, NaNs and points beyond the per-landmark cap are not stored.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

// A patch of surface seen again and again through a noisy sensor: the points go onto the surface
// before they take a voxel, so the noise along the normal adds no points after the first passes.
TEST(QuadricReconstruction, RepeatedNoisyViewsOfOnePatchDoNotGrowIt) {
  qs::PlaneShape shape;
  shape.normal = Eigen::Vector3d(0, 0, 1);
  const qs::QuadricModel floor = qs::quadricFromShape(shape);
  qs::SphereShape ball_shape;
  ball_shape.center = Eigen::Vector3d(0, 0, 1);
  ball_shape.radius = 0.3;
  const qs::QuadricModel ball = qs::quadricFromShape(ball_shape);
  const Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  std::mt19937 random(3);
  std::normal_distribution<float> depth_noise(0.f, 0.004f);  // 4 mm along the normal
  std::uniform_real_distribution<float> where(0.f, 0.2f);    // a 20 cm x 20 cm patch
  qs::QuadricReconstruction reconstruction;
  std::size_t after_first_passes = 0;
  for (int pass = 0; pass < 60; ++pass) {
    std::vector<Eigen::Vector3f> floor_points, ball_points;
    for (int i = 0; i < 2000; ++i) {
      floor_points.emplace_back(where(random), where(random), depth_noise(random));
      // The ball's cap facing -z: directions within the patch, radius perturbed.
      const Eigen::Vector3f direction =
          Eigen::Vector3f(where(random) - 0.1f, where(random) - 0.1f, -0.3f).normalized();
      ball_points.push_back(Eigen::Vector3f(0, 0, 1) + (0.3f + depth_noise(random)) * direction);
    }
    reconstruction.addPoints(1, floor, T_map_camera, floor_points);
    reconstruction.addPoints(2, ball, T_map_camera, ball_points);
    if (pass == 9)
      after_first_passes = reconstruction.size();
  }
  // The patch holds 20 x 20 voxels of floor plus the cap's (under 2 x its ~21 x 21 cm area: a
  // curved surface crosses voxel layers); noisy points off the surface would keep adding more.
  EXPECT_LE(reconstruction.size(1), 21u * 21u);
  EXPECT_LE(reconstruction.size(2), 2u * 22u * 22u);
  EXPECT_LE(reconstruction.size(), after_first_passes + after_first_passes / 50);
}

// The map-wide cap: once max_points are stored over all landmarks no landmark gains any, while
// merges and removals keep the count exact (a merge never adds points; a removal frees room).
TEST(QuadricReconstruction, MapWideCapBoundsEveryLandmarkTogether) {
  qs::PlaneShape shape;
  shape.normal = Eigen::Vector3d(0, 0, 1);
  const qs::QuadricModel floor = qs::quadricFromShape(shape);
  const Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> row;  // 40 points 2 cm apart: 40 voxels
  for (int i = 0; i < 40; ++i)
    row.emplace_back(0.02f * i, 0.f, 0.f);
  std::vector<Eigen::Vector3f> other_row = row;
  for (Eigen::Vector3f& p : other_row)
    p.y() = 0.5f;

  qs::QuadricReconstruction::Params params;
  params.max_points = 50;
  qs::QuadricReconstruction reconstruction(params);
  EXPECT_EQ(reconstruction.addPoints(1, floor, T_map_camera, row), 40);
  EXPECT_FALSE(reconstruction.full());
  EXPECT_EQ(reconstruction.addPoints(2, floor, T_map_camera, other_row), 10);
  EXPECT_TRUE(reconstruction.full());
  EXPECT_EQ(reconstruction.addPoints(3, floor, T_map_camera, row), 0);
  EXPECT_EQ(reconstruction.size(), 50u);
  EXPECT_EQ(reconstruction.cloud({{1, floor}, {2, floor}, {3, floor}}).size(), 50u);

  // Landmark 2 merged into 1 (same frame): its 10 points lie in voxels 1 does not hold.
  reconstruction.moveLandmark(2, 1, Eigen::Isometry3d::Identity());
  EXPECT_EQ(reconstruction.size(1), 50u);
  EXPECT_EQ(reconstruction.size(2), 0u);
  EXPECT_EQ(reconstruction.size(), 50u);

  reconstruction.removeLandmark(1);
  EXPECT_EQ(reconstruction.size(), 0u);
  EXPECT_FALSE(reconstruction.full());
  EXPECT_EQ(reconstruction.addPoints(3, floor, T_map_camera, row), 40);
  EXPECT_EQ(reconstruction.size(), 40u);
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
  params.max_points = 0;
  EXPECT_THROW(params.validate(), std::invalid_argument);
  params = {};
  params.max_surface_distance = -1.0;
  EXPECT_THROW(params.validate(), std::invalid_argument);
}

// A landmark merged into another (mapping/landmark_merger.h): its points join the survivor's at
// the same map positions, one per voxel, and the merged id has none left.
TEST(QuadricReconstruction, MovedLandmarkPointsKeepTheirPlaceInTheMap) {
  const Eigen::Isometry3d T_map_camera = cameraPose();
  // One floor z = 0 as two landmarks: frames at the origin and at (2, 0, 0) turned about the
  // normal.
  qs::PlaneShape shape;
  shape.normal = Eigen::Vector3d::UnitZ();
  const qs::QuadricModel floor_a = qs::quadricFromShape(shape);
  const qs::QuadricModel floor_b(
      qs::QuadricClass::kPlane,
      qs::makeIsometry(floor_a.pose().linear() *
                           Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                       Eigen::Vector3d(2, 0, 0)),
      Eigen::Vector3d::Ones());
  std::vector<Eigen::Vector3f> points_a, points_b;
  std::vector<Eigen::Vector3d> b_map;
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 10; ++j) {
      // 5 mm above the floor (they are stored projected onto it), in the middle of voxels (which
      // are centred on the grid lines) so that float rounding of the stored points cannot move
      // them across a voxel boundary.
      const Eigen::Vector3d pa(0.05 * i, 0.05 * j, 0.005), pb(1.5 + 0.05 * i, 0.05 * j, 0.005);
      points_a.push_back((T_map_camera.inverse() * pa).cast<float>());
      points_b.push_back((T_map_camera.inverse() * pb).cast<float>());
      b_map.push_back(pb - Eigen::Vector3d(0, 0, 0.005));  // where the cloud projects it
    }
  }
  qs::QuadricReconstruction reconstruction;
  ASSERT_EQ(reconstruction.addPoints(1, floor_a, T_map_camera, points_a), 200);
  ASSERT_EQ(reconstruction.addPoints(2, floor_b, T_map_camera, points_b), 200);
  const Eigen::Isometry3d T_a_b = floor_a.pose().inverse() * floor_b.pose();
  reconstruction.moveLandmark(2, 1, T_a_b);
  EXPECT_EQ(reconstruction.size(2), 0u);
  // x in [0, 0.95] and [1.5, 2.45]: no voxel in common.
  EXPECT_EQ(reconstruction.size(1), 400u);
  const auto cloud = reconstruction.cloud({{1, floor_a}});
  ASSERT_EQ(cloud.size(), 400u);
  for (const Eigen::Vector3d& p : b_map) {
    double nearest = 1e9;
    for (const auto& q : cloud)
      nearest = std::min(nearest, (q.getVector3fMap().cast<double>() - p).norm());
    EXPECT_LT(nearest, 1e-5);
  }
  for (const auto& q : cloud)
    EXPECT_EQ(q.label, 1u);
  // Moving the same points again adds nothing (one per voxel); an unknown id is a no-op.
  ASSERT_EQ(reconstruction.addPoints(3, floor_a, T_map_camera, points_a), 200);
  reconstruction.moveLandmark(3, 1, Eigen::Isometry3d::Identity());
  EXPECT_EQ(reconstruction.size(1), 400u);
  EXPECT_EQ(reconstruction.size(3), 0u);
  reconstruction.moveLandmark(42, 1, Eigen::Isometry3d::Identity());
  EXPECT_EQ(reconstruction.size(1), 400u);
}

// A merged landmark's points keep their colours on the survivor; the survivor's own uncoloured
// points stay uncoloured.
TEST(QuadricReconstruction, MovedPointsKeepTheirColours) {
  const Eigen::Isometry3d T_map_camera = cameraPose();
  qs::PlaneShape shape;
  shape.normal = Eigen::Vector3d::UnitZ();
  const qs::QuadricModel floor = qs::quadricFromShape(shape);
  std::vector<Eigen::Vector3f> points_a, points_b;
  for (int i = 0; i < 10; ++i) {
    points_a.push_back(
        (T_map_camera.inverse() * Eigen::Vector3d(0.005 + 0.05 * i, 0.005, 0.0)).cast<float>());
    points_b.push_back(
        (T_map_camera.inverse() * Eigen::Vector3d(0.005 + 0.05 * i, 0.505, 0.0)).cast<float>());
  }
  qs::QuadricReconstruction reconstruction;
  ASSERT_EQ(reconstruction.addPoints(1, floor, T_map_camera, points_a), 10);
  ASSERT_EQ(reconstruction.addPoints(2, floor, T_map_camera, points_b,
                                     std::vector<std::uint32_t>(10, 0xFF102030u)),
            10);
  reconstruction.moveLandmark(2, 1, Eigen::Isometry3d::Identity());
  int coloured = 0, plain = 0;
  for (const auto& p : reconstruction.cloud({{1, floor}})) {
    if (p.y > 0.25) {
      EXPECT_EQ(p.rgba, 0xFF102030u);
      ++coloured;
    } else {
      EXPECT_EQ(p.rgba >> 24, 0u);
      ++plain;
    }
  }
  EXPECT_EQ(coloured, 10);
  EXPECT_EQ(plain, 10);
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

// A landmark's estimate converges while its surface is seen again and again: a radius that grows by
// 4 cm and a centre that moves by 6 mm, a cylinder axis that moves by 8 mm, a plane merged with a
// parallel estimate of itself 1.5 cm away. The same patch keeps one point per cell of the surface
// (cells in the surface's own coordinates), where cells of the quadric frame's 3D grid gave every
// estimate a layer of its own (the long runs' reconstruction kept growing over a scene it had
// already seen).
TEST(QuadricReconstruction, AConvergingEstimateKeepsOnePointPerPatch) {
  const Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();  // looking along +z
  // The cap of a ball of radius 0.3 m at 1.5 m facing the camera, and a cylinder's side.
  std::vector<Eigen::Vector3f> ball_points, can_points;
  for (int i = 0; i < 30; ++i) {
    for (int j = 0; j < 30; ++j) {
      const Eigen::Vector3d direction =
          Eigen::Vector3d(-0.15 + 0.01 * i, -0.15 + 0.01 * j, -0.3).normalized();
      ball_points.push_back((Eigen::Vector3d(0, 0, 1.5) + 0.3 * direction).cast<float>());
      const double azimuth = -0.6 + 0.04 * i;  // around the vertical axis x = 0, z = 1.5
      can_points.push_back(Eigen::Vector3f(0.1 * std::sin(azimuth), -0.15 + 0.01 * j,
                                           1.5 - 0.1 * std::cos(azimuth)));
    }
  }
  qs::QuadricReconstruction reconstruction;
  std::size_t ball_first = 0, can_first = 0;
  for (int pass = 0; pass < 5; ++pass) {
    qs::SphereShape ball;
    ball.center = Eigen::Vector3d(0, 0, 1.5 + 0.003 * (pass - 2));
    ball.radius = 0.28 + 0.01 * pass;
    qs::CylinderShape can;
    can.point = Eigen::Vector3d(0.002 * (pass - 2), 0, 1.5);
    can.axis = Eigen::Vector3d::UnitY();
    can.radius = 0.09 + 0.005 * pass;
    reconstruction.addPoints(1, qs::quadricFromShape(ball), T_map_camera, ball_points);
    reconstruction.addPoints(2, qs::quadricFromShape(can), T_map_camera, can_points);
    if (pass == 0) {
      ball_first = reconstruction.size(1);
      can_first = reconstruction.size(2);
    }
  }
  std::printf("ball %zu -> %zu points, cylinder %zu -> %zu over 5 estimates\n", ball_first,
              reconstruction.size(1), can_first, reconstruction.size(2));
  ASSERT_GT(ball_first, 500u);
  ASSERT_GT(can_first, 300u);  // 11 cells of azimuth (1.2 rad at 0.11 rad) x 30 of height
  // Cells at the edge of the patch may change hands as the estimate moves under the cells (here
  // 1% of the ball's, 9% of the cylinder's: its axis moves by 8% of its radius), never a second
  // layer (3D cells of the quadric frame: 5.2x and 2.9x).
  EXPECT_LE(reconstruction.size(1), ball_first + ball_first / 10);
  EXPECT_LE(reconstruction.size(2), can_first + can_first / 7);

  // One floor patch mapped twice, as z = 0 and as z = 0.015 (another fragment's estimate), then
  // merged: the survivor holds the patch once.
  qs::PlaneShape floor_shape;
  floor_shape.normal = Eigen::Vector3d::UnitZ();
  const qs::QuadricModel floor = qs::quadricFromShape(floor_shape);
  floor_shape.offset = 0.015;
  const qs::QuadricModel raised = qs::quadricFromShape(floor_shape);
  std::vector<Eigen::Vector3f> floor_points;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      floor_points.emplace_back(0.003 + 0.01 * i, 0.003 + 0.01 * j, 0.007f);
  ASSERT_EQ(reconstruction.addPoints(3, floor, T_map_camera, floor_points), 400);
  ASSERT_EQ(reconstruction.addPoints(4, raised, T_map_camera, floor_points), 400);
  reconstruction.moveLandmark(4, 3, floor.pose().inverse() * raised.pose());
  EXPECT_EQ(reconstruction.size(3), 400u);
}
