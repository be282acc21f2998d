#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "../test_support.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {
namespace {

// Brute-force distance to a surface given as a parametric sampler (for the cone's truth).
double bruteForceConeDistance(const ConeShape& cone, const Eigen::Vector3d& p) {
  const Eigen::Matrix3d R = rotationWithAxis(cone.axis, 2);
  double best = 1e9;
  for (int i = 0; i < 720; ++i) {
    const double phi = 2 * M_PI * i / 720;
    const Eigen::Vector3d u(std::sin(cone.half_angle) * std::cos(phi),
                            std::sin(cone.half_angle) * std::sin(phi), std::cos(cone.half_angle));
    for (double sign : {1.0, -1.0}) {
      const Eigen::Vector3d dir = R * Eigen::Vector3d(u.x(), u.y(), sign * u.z());
      const double t = std::max(0.0, (p - cone.apex).dot(dir));
      best = std::min(best, (p - cone.apex - t * dir).norm());
    }
  }
  return best;
}

TEST(SurfaceDistance, ExactDistancesOfClassesOfRevolution) {
  const QuadricModel sphere = quadricFromShape(SphereShape{Eigen::Vector3d(1, 1, 1), 2.0});
  EXPECT_NEAR(exactDistance(sphere, Eigen::Vector3d(1, 1, 4)), 1.0, 1e-12);
  EXPECT_NEAR(exactDistance(sphere, Eigen::Vector3d(1, 1, 1.5)), 1.5, 1e-12);
  const QuadricModel cyl =
      quadricFromShape(CylinderShape{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), 1.0});
  EXPECT_NEAR(exactDistance(cyl, Eigen::Vector3d(50, 3, 0)), 2.0, 1e-12);
  std::mt19937 rng(81);
  const ConeShape cone{Eigen::Vector3d(0.5, -1, 2), Eigen::Vector3d(1, 2, -1).normalized(), 0.5};
  const QuadricModel q = quadricFromShape(cone);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d p = test::randomVector(rng, 3.0);
    EXPECT_NEAR(exactDistance(q, p), bruteForceConeDistance(cone, p), 2e-3 * (1 + p.norm()));
  }
}

TEST(SurfaceDistance, FirstOrderApproximatesExactNearTheSurface) {
  std::mt19937 rng(82);
  for (QuadricClass c : {QuadricClass::kSphere, QuadricClass::kCylinder, QuadricClass::kCone}) {
    const QuadricModel q = test::randomQuadric(c, rng);
    SurfaceProjector projector;
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d on = projector.project(q, q.pose() * test::randomVector(rng, 2.0));
      const Eigen::Vector3d n = algebraicGradient(q, on).normalized();
      const double eps = 1e-4;
      const Eigen::Vector3d p = on + eps * n;
      // second-order agreement: |first - exact| = O(eps^2)
      EXPECT_NEAR(firstOrderDistance(q, p), exactDistance(q, p), 1e-6) << toString(c);
    }
  }
  // The double plane (alpha x)^2 vanishes to second order: |f|/|grad f| is half the distance.
  const QuadricModel plane = quadricFromShape(PlaneShape{Eigen::Vector3d::UnitZ(), 0});
  EXPECT_NEAR(firstOrderDistance(plane, Eigen::Vector3d(1, 2, 0.4)), 0.2, 1e-12);
  EXPECT_NEAR(exactDistance(plane, Eigen::Vector3d(1, 2, 0.4)), 0.4, 1e-12);
}

TEST(SurfaceProjector, ProjectsOntoTheClosestSurfacePoint) {
  std::mt19937 rng(83);
  SurfaceProjector projector;
  for (QuadricClass c : {QuadricClass::kPlane, QuadricClass::kSphere, QuadricClass::kCylinder,
                         QuadricClass::kCone}) {
    const QuadricModel q = test::randomQuadric(c, rng);
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d p = test::randomVector(rng, 3.0);
      const Eigen::Vector3d s = projector.project(q, p);
      EXPECT_LT(exactDistance(q, s), 1e-9) << toString(c);     // on the surface
      EXPECT_NEAR((p - s).norm(), exactDistance(q, p), 1e-9);  // and the closest point
    }
  }
}

TEST(SurfaceDistance, ValueAndSlopeAgreeWithValueAndGradient) {
  std::mt19937 rng(85);
  for (const QuadricClass c : {QuadricClass::kGeneral, QuadricClass::kCylinder, QuadricClass::kCone,
                               QuadricClass::kSphere}) {
    const QuadricModel q = test::randomQuadric(c, rng);
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d p = q.pose() * test::randomVector(rng, 1.0);
      const AlgebraicValue a = algebraicValueAndSlope(q, p);
      const double f = algebraicDistance(q, p);
      const double g = algebraicGradient(q, p).norm();
      EXPECT_NEAR(a.value, f, 1e-12 * std::max(1.0, std::abs(f)));
      EXPECT_NEAR(a.gradient_norm, g, 1e-12 * std::max(1.0, g));
      EXPECT_GT(g, 0.0);
    }
  }
}

TEST(SurfaceProjector, GeneralQuadricsConvergeToTheSurface) {
  std::mt19937 rng(84);
  SurfaceProjector projector;
  for (const Eigen::Vector4d& sig : {Eigen::Vector4d(1, 1, 1, -1), Eigen::Vector4d(1, 1, -1, -1),
                                     Eigen::Vector4d(1, 1, -1, 1)}) {
    const QuadricModel q = test::randomQuadric(QuadricClass::kGeneral, rng, sig);
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d p = q.pose() * test::randomVector(rng, 1.0);
      const Eigen::Vector3d s = projector.project(q, p);
      EXPECT_LT(firstOrderDistance(q, s), 1e-9);
      // Not farther than the distance along the gradient-normal would allow grossly.
      EXPECT_LT((s - p).norm(), 5.0);
    }
  }
  EXPECT_THROW(
      exactDistance(test::randomQuadric(QuadricClass::kGeneral, rng), Eigen::Vector3d::Zero()),
      std::invalid_argument);
}

TEST(SurfaceProjector, ParamsValidate) {
  SurfaceProjector::Params p;
  p.max_iterations = 0;
  EXPECT_THROW(SurfaceProjector{p}, std::invalid_argument);
  p = SurfaceProjector::Params();
  p.tolerance = 0;
  EXPECT_THROW(SurfaceProjector{p}, std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
