// rayResidual: a point moved along its camera ray by a known offset off a sphere, a cylinder, a
// cone and a general quadric fitted to ellipsoid samples reads that offset back (signed: positive
// when the surface lies beyond the point); a ray beside the surface misses; rayResidualStats counts
// misses and residuals beyond the cap as the cap.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/frontend/primitive_shape.h"
#include "quadric_slam/frontend/ray_residual.h"

namespace qs = quadric_slam;

namespace {

// The point where the camera ray through `direction` first meets the surface (distance along the
// ray found by bisection on the sign of the shape's distance, from the camera to `far`).
Eigen::Vector3d firstHit(const qs::PrimitiveShape& shape, const Eigen::Vector3d& direction,
                         double near, double far) {
  const Eigen::Vector3d r = direction.normalized();
  double a = near, b = far;
  const double sign_a = std::copysign(1.0, shape.distance(a * r));
  for (int i = 0; i < 100; ++i) {
    const double m = 0.5 * (a + b);
    (std::copysign(1.0, shape.distance(m * r)) == sign_a ? a : b) = m;
  }
  return 0.5 * (a + b) * r;
}

void expectOffsetsReadBack(const qs::PrimitiveShape& shape, const Eigen::Vector3d& direction,
                           double near, double far) {
  const Eigen::Matrix4d Q = shape.quadric().matrix();
  const Eigen::Vector3d hit = firstHit(shape, direction, near, far);
  ASSERT_LT(std::abs(shape.distance(hit)), 1e-9);
  const Eigen::Vector3d r = hit.normalized();
  for (const double offset : {-0.02, -0.005, 0.0, 0.005, 0.02}) {
    // The point measured `offset` too near: the surface lies `offset` beyond it.
    const std::optional<double> t = qs::rayResidual(Q, hit - offset * r);
    ASSERT_TRUE(t) << "offset " << offset;
    EXPECT_NEAR(*t, offset, 1e-9) << "offset " << offset;
  }
}

}  // namespace

TEST(RayResidual, ReadsBackOffsetsAlongTheRay) {
  // A sphere 2 m ahead, a ray through its side (oblique incidence).
  expectOffsetsReadBack(qs::PrimitiveShape::sphere(Eigen::Vector3d(0.1, -0.05, 2.0), 0.2),
                        Eigen::Vector3d(0.12, 0.0, 1.0), 0.5, 2.0);
  // A vertical cylinder (camera y is down) of radius 0.15 m, 2.1 m ahead and to the left.
  expectOffsetsReadBack(
      qs::PrimitiveShape::cylinder(Eigen::Vector3d(-0.6, 0.0, 2.1), Eigen::Vector3d(0, 1, 0), 0.15),
      Eigen::Vector3d(-0.26, 0.1, 1.0), 0.5, 2.1);
  // A cone, apex above, opening downwards, half angle 0.32 rad.
  expectOffsetsReadBack(
      qs::PrimitiveShape::cone(Eigen::Vector3d(0.2, -0.5, 2.4), Eigen::Vector3d(0, 1, 0), 0.32),
      Eigen::Vector3d(0.08, 0.1, 1.0), 0.5, 2.4);
}

TEST(RayResidual, ARayBesideTheSurfaceMisses) {
  const Eigen::Matrix4d Q =
      qs::PrimitiveShape::sphere(Eigen::Vector3d(0, 0, 2.0), 0.2).quadric().matrix();
  EXPECT_FALSE(qs::rayResidual(Q, Eigen::Vector3d(0.3, 0.0, 2.0)));
  EXPECT_FALSE(qs::rayResidual(Q, Eigen::Vector3d::Zero()));  // no ray at the camera centre
  EXPECT_TRUE(qs::rayResidual(Q, Eigen::Vector3d(0.0, 0.0, 1.9)));
}

TEST(RayResidual, GeneralQuadricMatrixIsTheFittedSurface) {
  // Exact samples of the camera-facing side of an ellipsoid 1.5 m ahead.
  const Eigen::Vector3d centre(0.1, -0.2, 1.5), radii(0.13, 0.08, 0.07);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 40; ++i) {
    for (int j = 0; j < 20; ++j) {
      const double azimuth = 2 * M_PI * i / 40, polar = M_PI / 2 + M_PI / 2 * (j + 0.5) / 20;
      const Eigen::Vector3d u(std::sin(polar) * std::cos(azimuth),
                              std::sin(polar) * std::sin(azimuth), std::cos(polar));
      points.push_back(centre + radii.cwiseProduct(u));
    }
  }
  const qs::GeneralQuadricFit fit = qs::fitGeneralQuadric(points);
  ASSERT_TRUE(fit.ok);
  const Eigen::Matrix4d Q = fit.matrix();
  for (std::size_t k = 0; k < points.size(); k += 37) {
    const std::optional<double> on = qs::rayResidual(Q, points[k]);
    ASSERT_TRUE(on);
    EXPECT_NEAR(*on, 0.0, 1e-6);
  }
  // A point 1 cm nearer than the surface along the ray through the ellipsoid's nearest point.
  const Eigen::Vector3d nearest = centre - Eigen::Vector3d(0, 0, radii.z());
  const std::optional<double> t = qs::rayResidual(Q, nearest - 0.01 * nearest.normalized());
  ASSERT_TRUE(t);
  EXPECT_NEAR(*t, 0.01, 1e-4);
}

TEST(RayResidual, StatisticsCapMissesAndLargeResiduals) {
  const Eigen::Matrix4d Q =
      qs::PrimitiveShape::sphere(Eigen::Vector3d(0, 0, 2.0), 0.2).quadric().matrix();
  const std::vector<Eigen::Vector3d> points = {
      Eigen::Vector3d(0, 0, 1.79),   // 1 cm before the surface
      Eigen::Vector3d(0, 0, 1.70),   // 10 cm before: capped at 3 cm
      Eigen::Vector3d(0.3, 0, 2.0),  // miss: 3 cm
      Eigen::Vector3d(0, 0, 1.80)};  // on the surface
  const qs::RayResidualStats stats = qs::rayResidualStats(Q, points, 0.03);
  EXPECT_NEAR(stats.miss_share, 0.25, 1e-12);
  EXPECT_NEAR(stats.rms, std::sqrt((0.01 * 0.01 + 2 * 0.03 * 0.03) / 4), 1e-9);
  EXPECT_EQ(qs::rayResidualStats(Q, {}, 0.03).rms, 0.0);
}
