// fitGeneralQuadric: exact and noisy samples of an ellipsoid, a sphere and a cylinder patch as seen
// by a depth camera (one side): the Sampson RMS is ~0 on exact samples and ~ the noise on noisy
// ones; a sphere fitted to the ellipsoid has an RMS well above the general quadric's (what the
// segmenter's shape test relies on) while on a true sphere the two agree.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace qs = quadric_slam;

namespace {

// The camera-facing half of an ellipsoid with semi-axes r centred at c (camera at the origin,
// looking along +z), with isotropic Gaussian noise.
std::vector<Eigen::Vector3d> ellipsoidPatch(const Eigen::Vector3d& c, const Eigen::Vector3d& r,
                                            double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<Eigen::Vector3d> points;
  while (points.size() < 1500) {
    Eigen::Vector3d u(uni(rng), uni(rng), uni(rng));
    if (u.norm() < 0.1 || u.norm() > 1)
      continue;
    u.normalize();
    if (u.z() > -0.2)  // keep the side facing the camera
      continue;
    points.push_back(c + r.cwiseProduct(u) + Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)));
  }
  return points;
}

}  // namespace

TEST(GeneralQuadricFit, ExactSamplesFitExactly) {
  const auto points =
      ellipsoidPatch(Eigen::Vector3d(0.1, -0.2, 1.5), Eigen::Vector3d(0.13, 0.08, 0.07), 0.0, 1);
  const qs::GeneralQuadricFit fit = qs::fitGeneralQuadric(points);
  ASSERT_TRUE(fit.ok);
  EXPECT_LT(fit.rms, 1e-6);
  // A point off the surface is at about its offset.
  const Eigen::Vector3d off = Eigen::Vector3d(0.1, -0.2, 1.5) + Eigen::Vector3d(0, 0, -0.08);
  EXPECT_NEAR(std::abs(fit.distance(off)), 0.01, 0.003);
}

TEST(GeneralQuadricFit, SeparatesAnEllipsoidFromASphere) {
  const double noise = 0.002;
  const Eigen::Vector3d c(0.1, -0.2, 1.5);
  for (unsigned seed = 1; seed <= 3; ++seed) {
    // The cushion of the synthetic desk scene: an ellipsoid taken as a sphere.
    const auto cushion = ellipsoidPatch(c, Eigen::Vector3d(0.13, 0.08, 0.07), noise, seed);
    const qs::GeneralQuadricFit general = qs::fitGeneralQuadric(cushion);
    ASSERT_TRUE(general.ok);
    EXPECT_NEAR(general.rms, noise, 0.5 * noise) << "seed " << seed;
    const qs::ShapeRefiner::Result sphere =
        qs::ShapeRefiner().refine(qs::fitSphereAlgebraic(cushion), cushion);
    EXPECT_GT(sphere.rms, 1.5 * general.rms) << "seed " << seed;

    // A true sphere: the sphere fit is as good as the general quadric.
    const auto globe = ellipsoidPatch(c, Eigen::Vector3d::Constant(0.15), noise, seed + 10);
    const qs::GeneralQuadricFit general_globe = qs::fitGeneralQuadric(globe);
    const qs::ShapeRefiner::Result sphere_globe =
        qs::ShapeRefiner().refine(qs::fitSphereAlgebraic(globe), globe);
    EXPECT_LT(sphere_globe.rms, 1.1 * general_globe.rms) << "seed " << seed;
    EXPECT_NEAR(sphere_globe.shape.size, 0.15, 0.003);
  }
}

TEST(GeneralQuadricFit, TooFewPointsIsNotOk) {
  EXPECT_FALSE(qs::fitGeneralQuadric(std::vector<Eigen::Vector3d>(10, Eigen::Vector3d::Ones())).ok);
}

// The fit's analytic Jacobian row (d Sampson distance / d coefficients) against central differences,
// at random coefficients and points.
TEST(GeneralQuadricFit, SampsonJacobianMatchesNumericDifferentiation) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::Matrix<double, 10, 1> c;
    for (int j = 0; j < 10; ++j)
      c[j] = uni(rng);
    c.normalize();
    const Eigen::Vector3d x(uni(rng), uni(rng), uni(rng));
    Eigen::Matrix<double, 10, 1> analytic;
    const double r = qs::sampsonDistance(c, x, &analytic);
    EXPECT_DOUBLE_EQ(r, qs::sampsonDistance(c, x));
    constexpr double h = 1e-7;
    for (int j = 0; j < 10; ++j) {
      Eigen::Matrix<double, 10, 1> plus = c, minus = c;
      plus[j] += h;
      minus[j] -= h;
      const double numeric =
          (qs::sampsonDistance(plus, x) - qs::sampsonDistance(minus, x)) / (2 * h);
      EXPECT_NEAR(analytic[j], numeric, 1e-5 * (1 + std::abs(numeric)))
          << "trial " << trial << " coefficient " << j;
    }
  }
}
