// The segmenter's starting shapes (curved_shape_starts.h) on exact and noisy samples of the visible
// side of a surface: a cone and a cylinder recovered from points and normals alone, a cone from a
// cylinder fit of a cone's points, a cylinder from a thin cone, and the shape curvature.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "axial_surface_samples.h"
#include "quadric_slam/frontend/curved_shape_starts.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace qs = quadric_slam;
using qs::PrimitiveShape;

namespace {

using Samples = qs::test::SurfaceSamples;
using qs::test::axialSurface;

double angleBetweenAxes(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

}  // namespace

TEST(CurvedShapeStarts, ConeFromNormalsRecoversApexAxisAndHalfAngle) {
  const double half_angle = 0.35;
  const Samples s = axialSurface(true, half_angle, 0.2, 0.5, 0.0, 1);
  const PrimitiveShape cone = qs::coneFromNormals(s.points, s.normals);
  EXPECT_NEAR((cone.point - Eigen::Vector3d(0.1, -0.3, 1.6)).norm(), 0.0, 1e-6);
  EXPECT_LT(angleBetweenAxes(cone.direction, Eigen::Vector3d::UnitY()), 1e-6);
  EXPECT_GT(cone.direction.y(), 0);  // from the apex into the opening
  EXPECT_NEAR(cone.size, half_angle, 1e-6);
  // Too few points: degenerate (half angle 0).
  const std::vector<Eigen::Vector3d> few(s.points.begin(), s.points.begin() + 5);
  const std::vector<Eigen::Vector3d> few_normals(s.normals.begin(), s.normals.begin() + 5);
  EXPECT_EQ(qs::coneFromNormals(few, few_normals).size, 0.0);
}

TEST(CurvedShapeStarts, CylinderFromNormalsRecoversAxisAndRadiusUnderNoise) {
  const double radius = 0.06;
  const Samples s = axialSurface(false, radius, -0.2, 0.2, 0.002, 2);
  const PrimitiveShape cylinder = qs::cylinderFromNormals(s.points, s.normals, 1.0 / radius);
  EXPECT_LT(angleBetweenAxes(cylinder.direction, Eigen::Vector3d::UnitY()), 0.02);
  EXPECT_NEAR(cylinder.size, radius, 1e-12);  // the curvature given
  // The axis passes within a few millimetres of the true one.
  const Eigen::Vector3d v = cylinder.point - Eigen::Vector3d(0.1, -0.3, 1.6);
  EXPECT_LT((v - v.dot(cylinder.direction) * cylinder.direction).norm(), 0.005);
  EXPECT_EQ(qs::cylinderFromNormals(s.points, s.normals, 0.0).size, 0.0);
}

TEST(CurvedShapeStarts, ConeFromCylinderAndCylinderFromConeRoundTheAxis) {
  const double half_angle = 0.3;
  const Samples s = axialSurface(true, half_angle, 0.2, 0.5, 0.0, 3);
  // A cylinder on the cone's axis: the linear radius profile gives back the cone.
  const PrimitiveShape axis_cylinder =
      PrimitiveShape::cylinder(Eigen::Vector3d(0.1, 0.0, 1.6), Eigen::Vector3d::UnitY(), 0.1);
  const PrimitiveShape cone = qs::coneFromCylinder(axis_cylinder, s.points);
  EXPECT_NEAR((cone.point - Eigen::Vector3d(0.1, -0.3, 1.6)).norm(), 0.0, 1e-6);
  EXPECT_NEAR(cone.size, half_angle, 1e-6);
  EXPECT_GT(cone.direction.y(), 0);
  // The cylinder of a cone: on the same axis, with the points' mean distance to it as radius.
  const PrimitiveShape cylinder = qs::cylinderFromCone(cone, s.points);
  EXPECT_LT(angleBetweenAxes(cylinder.direction, Eigen::Vector3d::UnitY()), 1e-6);
  double mean_rho = 0;
  for (const auto& p : s.points) {
    const Eigen::Vector3d v = p - Eigen::Vector3d(0.1, -0.3, 1.6);
    mean_rho += (v - v.y() * Eigen::Vector3d::UnitY()).norm();
  }
  EXPECT_NEAR(cylinder.size, mean_rho / s.points.size(), 1e-6);
  // A true cylinder's points have no radius slope: no cone (half angle 0).
  const Samples c = axialSurface(false, 0.08, -0.2, 0.2, 0.0, 4);
  EXPECT_EQ(qs::coneFromCylinder(axis_cylinder, c.points).size, 0.0);
}

TEST(CurvedShapeStarts, ShapeCurvatureIsOneOverRadiusOrTheConesMeanCurvature) {
  const std::vector<Eigen::Vector3d> none;
  EXPECT_DOUBLE_EQ(qs::shapeCurvature(PrimitiveShape::sphere(Eigen::Vector3d(0, 0, 2), 0.25), none),
                   4.0);
  EXPECT_DOUBLE_EQ(
      qs::shapeCurvature(
          PrimitiveShape::cylinder(Eigen::Vector3d(0, 0, 2), Eigen::Vector3d::UnitY(), 0.05), none),
      20.0);
  // A cone point at distance rho from the axis: curvature cos(half angle) / rho.
  const PrimitiveShape cone =
      PrimitiveShape::cone(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), 0.4);
  const std::vector<Eigen::Vector3d> at_rho = {Eigen::Vector3d(0.1, 0.5, 0)};
  EXPECT_NEAR(qs::shapeCurvature(cone, at_rho), std::cos(0.4) / 0.1, 1e-12);
}

// A cylinder fitted to the visible side of a cone tilts its axis to follow the near generator:
// along that axis the radius hardly changes and coneFromCylinder gives a thin cone; with the axis
// tilted the right way the regression sees the opening and the refinement reaches the cone.
TEST(CurvedShapeStarts, ConeFromTiltedCylinderFindsTheOpeningACylinderFitHides) {
  const double half_angle = 0.32;
  const Samples s = axialSurface(true, half_angle, 0.2, 0.6, 0.002, 5);
  const qs::ShapeRefiner refiner;
  const qs::ShapeRefiner::Result cylinder = refiner.refine(
      qs::cylinderFromCone(qs::coneFromNormals(s.points, s.normals), s.points), s.points);
  ASSERT_TRUE(cylinder.ok);
  ASSERT_EQ(cylinder.shape.quadric_class, qs::QuadricClass::kCylinder);
  EXPECT_GT(angleBetweenAxes(cylinder.shape.direction, Eigen::Vector3d::UnitY()), 0.15)
      << "the fitted cylinder follows the near generator";
  EXPECT_LT(qs::coneFromCylinder(cylinder.shape, s.points).size, 0.1);
  double best_rms = 1e9, best_half_angle = 0, best_axis_error = 1;
  for (double sign : {1.0, -1.0}) {
    const qs::ShapeRefiner::Result cone =
        refiner.refine(qs::coneFromTiltedCylinder(cylinder.shape, s.points, 0.3, sign), s.points);
    if (cone.ok && cone.rms < best_rms) {
      best_rms = cone.rms;
      best_half_angle = cone.shape.size;
      best_axis_error = angleBetweenAxes(cone.shape.direction, Eigen::Vector3d::UnitY());
    }
  }
  EXPECT_NEAR(best_half_angle, half_angle, 0.02);
  EXPECT_LT(best_axis_error, 0.02);
  EXPECT_LT(best_rms, 0.8 * cylinder.rms);
}

TEST(CurvedShapeStarts, CylinderCurvatureFromNormalsIsOneOverTheRadius) {
  const double radius = 0.06;
  const Samples exact = axialSurface(false, radius, -0.2, 0.2, 0.0, 5);
  EXPECT_NEAR(qs::cylinderCurvatureFromNormals(exact.points, exact.normals), 1.0 / radius, 1e-6);
  const Samples noisy = axialSurface(false, radius, -0.2, 0.2, 0.002, 6);
  EXPECT_NEAR(qs::cylinderCurvatureFromNormals(noisy.points, noisy.normals), 1.0 / radius,
              0.1 / radius);
  // A plane's normals do not turn; too few points are degenerate.
  std::vector<Eigen::Vector3d> plane, normals;
  for (int i = 0; i < 100; ++i) {
    plane.emplace_back(0.01 * (i % 10), 0.01 * (i / 10), 1.5);
    normals.emplace_back(0, 0, -1);
  }
  EXPECT_NEAR(qs::cylinderCurvatureFromNormals(plane, normals), 0.0, 1e-9);
  EXPECT_EQ(qs::cylinderCurvatureFromNormals({plane.begin(), plane.begin() + 5},
                                             {normals.begin(), normals.begin() + 5}),
            0.0);
}
