// ConstrainedDirections: the degeneracy test of point-to-plane ICP judged against the normals'
// noise. Normal matrices are built from simulated correspondences on planes whose normals carry
// a known angular noise, as far surfaces of a structured-light sensor give them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "quadric_slam/odometry/constrained_directions.h"

namespace quadric_slam {
namespace {

struct PlanePatch {
  Eigen::Vector3d normal;  // unit, camera frame
  Eigen::Vector3d centre;  // a point of the patch (m)
  Eigen::Vector3d u, v;    // unit directions spanning the patch
  double half_size;        // m
};

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Matrix6d noise = Matrix6d::Zero();
};

Eigen::Vector3d tangentNoise(const Eigen::Vector3d& n, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> gauss(0.0, sigma);
  Eigen::Vector3d e(gauss(rng), gauss(rng), gauss(rng));
  return e - n.dot(e) * n;
}

// H from the keyframe normals (true normal + noise) and the noise part as PointToPlaneIcp
// estimates it: half the outer products of the Jacobians of the two normals' tangential difference.
NormalEquations simulate(const std::vector<PlanePatch>& patches, int points_per_patch,
                         double normal_sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  NormalEquations eq;
  for (const PlanePatch& patch : patches) {
    for (int i = 0; i < points_per_patch; ++i) {
      const Eigen::Vector3d p =
          patch.centre + patch.half_size * (uniform(rng) * patch.u + uniform(rng) * patch.v);
      const Eigen::Vector3d n_key =
          (patch.normal + tangentNoise(patch.normal, normal_sigma, rng)).normalized();
      const Eigen::Vector3d n_current =
          (patch.normal + tangentNoise(patch.normal, normal_sigma, rng)).normalized();
      Vector6d J;
      J << n_key, p.cross(n_key);
      eq.H += J * J.transpose();
      Eigen::Vector3d d = n_current - n_key;
      d -= n_key.dot(d) * n_key;
      Vector6d Jd;
      Jd << d, p.cross(d);
      eq.noise += 0.5 * Jd * Jd.transpose();
    }
  }
  return eq;
}

// A wall facing the camera 4 m ahead (camera z forward), 3 m wide.
PlanePatch farWall() {
  return {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, 4.0), Eigen::Vector3d::UnitX(),
          Eigen::Vector3d::UnitY(), 1.5};
}

// A corner 3-4.5 m away: two walls meeting ahead of the camera, and the floor below it, each
// 2.4 m across.
std::vector<PlanePatch> farCorner() {
  const double s = std::sqrt(0.5);
  return {
      {Eigen::Vector3d(s, 0, -s), Eigen::Vector3d(-0.8, 0, 3.8), Eigen::Vector3d(s, 0, s),
       Eigen::Vector3d::UnitY(), 1.2},
      {Eigen::Vector3d(-s, 0, -s), Eigen::Vector3d(0.8, 0, 3.8), Eigen::Vector3d(-s, 0, s),
       Eigen::Vector3d::UnitY(), 1.2},
      {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 1.4, 3.2), Eigen::Vector3d::UnitX(),
       Eigen::Vector3d::UnitZ(), 1.2},
  };
}

constexpr double kRatio = 2e-3;  // config/odometry.yaml min_eigenvalue_ratio
constexpr double kFactor = 3.0;  // a noise_information_factor

TEST(ConstrainedDirections, NoisyNormalsOfOneFarPlaneDoNotConstrainMotionAlongIt) {
  // 15 degrees of normal noise, as on a Kinect v1 surface 3-4 m away.
  const NormalEquations eq = simulate({farWall()}, 2000, 15.0 * M_PI / 180.0, 1);
  // The eigenvalue-ratio test alone is fooled: the noise spreads the normals enough.
  const ConstrainedDirections ratio_only(eq.H, eq.noise, kRatio, 0.0);
  ASSERT_EQ(ratio_only.constrained(), 6) << "eigenvalue ratio " << ratio_only.eigenvalueRatio();
  // Judged against the noise: only the distance to the wall and its two tilts are constrained.
  const ConstrainedDirections judged(eq.H, eq.noise, kRatio, kFactor);
  EXPECT_EQ(judged.constrained(), 3);
  EXPECT_LT(ConstrainedDirections::informationOverNoise(eq.H, eq.noise), kFactor);
  // The covariance says the free directions are unknown.
  const Matrix6d cov = judged.covariance(1e-6, 1.0);
  EXPECT_GT(cov(0, 0), 0.5);
  EXPECT_GT(cov(1, 1), 0.5);
  EXPECT_LT(cov(2, 2), 1e-3);  // the distance to the wall is measured
}

TEST(ConstrainedDirections, AStepOnOneFarPlaneDoesNotSlideAlongIt) {
  // The measured directions of a wall are its distance and two tilts. A residual that asks for
  // them (any b) must move the camera only there: no translation along the wall (x, y), no turn
  // about its normal. The noise couples a slide along the wall with a tilt (the normals' noise is
  // tangential, its lever arm the 4 m to the wall), so a step along the constrained generalised
  // eigenvectors slid the camera by centimetres a frame on real-looking data.
  const NormalEquations eq = simulate({farWall()}, 2000, 15.0 * M_PI / 180.0, 1);
  const ConstrainedDirections judged(eq.H, eq.noise, kRatio, kFactor);
  ASSERT_EQ(judged.constrained(), 3);
  // The normal equations of a camera 1 cm nearer the wall and tilted by 0.2 degrees about x.
  Vector6d truth;
  truth << 0, 0, 0.01, 0.2 * M_PI / 180.0, 0, 0;
  const Vector6d step = judged.step(-eq.H * truth);
  EXPECT_LT(std::abs(step(0)), 1e-4) << step.transpose();
  EXPECT_LT(std::abs(step(1)), 1e-4) << step.transpose();
  EXPECT_LT(std::abs(step(5)), 1e-4) << step.transpose();
  EXPECT_NEAR(step(2), truth(2), 1e-3) << step.transpose();
  EXPECT_NEAR(step(3), truth(3), 1e-3) << step.transpose();
}

TEST(ConstrainedDirections, AFarCornerStillConstrainsEveryDirection) {
  const NormalEquations eq = simulate(farCorner(), 1000, 15.0 * M_PI / 180.0, 2);
  const ConstrainedDirections judged(eq.H, eq.noise, kRatio, kFactor);
  EXPECT_EQ(judged.constrained(), 6) << "weakest margin " << judged.weakestMargin();
  EXPECT_GT(ConstrainedDirections::informationOverNoise(eq.H, eq.noise), kFactor);
}

TEST(ConstrainedDirections, WithoutNoiseItIsTheEigenvalueRatioTest) {
  // Eigenvalues 1..1 and 1e-4 along a rotated direction: below a ratio of 1e-3.
  Matrix6d Q = Matrix6d(Eigen::HouseholderQR<Matrix6d>(Matrix6d::Random()).householderQ());
  Vector6d lambda;
  lambda << 1e-4, 0.5, 1.0, 2.0, 3.0, 4.0;
  const Matrix6d H = Q * lambda.asDiagonal() * Q.transpose();
  const ConstrainedDirections directions(H, Matrix6d::Zero(), 1e-3, kFactor);
  ASSERT_EQ(directions.constrained(), 5);
  EXPECT_NEAR(directions.eigenvalueRatio(), 1e-4 / 4.0, 1e-9);
  // The step is H^-1 (-b) with the weak direction removed.
  const Vector6d b = Vector6d::Random();
  Vector6d expected = Vector6d::Zero();
  for (int i = 1; i < 6; ++i)
    expected -= Q.col(i) * (Q.col(i).dot(b) / lambda(i));
  EXPECT_LT((directions.step(b) - expected).norm(), 1e-9);
  // All constrained: the full Gauss-Newton solution.
  const ConstrainedDirections loose(H, Matrix6d::Zero(), 1e-6, kFactor);
  ASSERT_EQ(loose.constrained(), 6);
  EXPECT_LT((loose.step(b) + H.ldlt().solve(b)).norm(), 1e-6);
  EXPECT_LT((loose.covariance(2.0, 1.0) - 2.0 * H.inverse()).norm(), 1e-6);
  EXPECT_TRUE(std::isinf(ConstrainedDirections::informationOverNoise(H, Matrix6d::Zero())));
}

TEST(ConstrainedDirections, NoInformationConstrainsNothing) {
  const ConstrainedDirections none(Matrix6d::Zero(), Matrix6d::Zero(), kRatio, kFactor);
  EXPECT_EQ(none.constrained(), 0);
  EXPECT_EQ(none.step(Vector6d::Ones()).norm(), 0.0);
  EXPECT_GT(none.covariance(1.0, 1.0)(3, 3), 0.5);
}

}  // namespace
}  // namespace quadric_slam
