// linearizeObservation computes the observation residual's tangent Jacobians directly
// (QuadricObservationCost::evaluateTangent). Checked against the two other ways of getting them:
// the Ceres path (ambient Jacobians of Evaluate times the blocks' PlusJacobians) and central
// differences through the manifolds' Plus, for every class, away from the measurement.
#include <gtest/gtest.h>

#include <array>
#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/observation_linearization.h"

namespace quadric_slam {
namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

Eigen::VectorXd gaussian(std::mt19937& rng, int n, double sigma) {
  std::normal_distribution<double> g(0.0, sigma);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i)
    v[i] = g(rng);
  return v;
}

void expectLinearizationMatchesCostAndDifferences(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  const int k = minimalDimension(c);
  const PoseManifold pose_manifold;
  const QuadricManifold quadric_manifold(c);
  for (int trial = 0; trial < 10; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const QuadricModel truth = test::randomQuadric(c, rng);
    const Eigen::Isometry3d T_true = test::randomPose(rng);
    // The measurement in another frame of its surface, the state away from it: the symmetry
    // alignment and both rates of the Jacobian take part, with a residual far from zero.
    const QuadricModel h = predictMeasurement(T_true, truth);
    const QuadricModel z(c, h.pose() * test::randomSymmetry(c, rng), h.scale(), h.signature());
    const QuadricModel landmark = truth.plusMinimal(gaussian(rng, k, 0.2));
    const Eigen::Isometry3d T_map_camera = plus(T_true, gaussian(rng, 6, 0.1));

    const ObservationLinearization lin = linearizeObservation(z, T_map_camera, landmark);
    ASSERT_TRUE(lin.valid);
    ASSERT_EQ(lin.residual.size(), k);
    ASSERT_EQ(lin.J_camera.rows(), k);
    ASSERT_EQ(lin.J_quadric.rows(), k);
    ASSERT_EQ(lin.J_quadric.cols(), k);
    EXPECT_GT(lin.residual.norm(), 1e-3);

    // The Ceres path with the unwhitened cost (L = I).
    const QuadricObservationCost cost(z, Eigen::MatrixXd::Identity(k, k));
    std::array<double, kPoseParameterSize> pose;
    std::array<double, kQuadricParameterSize> quadric;
    poseToParameters(T_map_camera, pose.data());
    quadricToParameters(landmark, quadric.data());
    const double* blocks[2] = {pose.data(), quadric.data()};
    Eigen::VectorXd residual(k);
    RowMajor J_pose(k, kPoseParameterSize), J_quadric(k, kQuadricParameterSize);
    double* jacobians[2] = {J_pose.data(), J_quadric.data()};
    ASSERT_TRUE(cost.Evaluate(blocks, residual.data(), jacobians));
    RowMajor plus_pose(kPoseParameterSize, 6), plus_quadric(kQuadricParameterSize, k);
    pose_manifold.PlusJacobian(pose.data(), plus_pose.data());
    quadric_manifold.PlusJacobian(quadric.data(), plus_quadric.data());
    EXPECT_LT(test::relativeError(lin.residual, residual), 1e-12);
    EXPECT_LT(test::relativeError(lin.J_camera, J_pose * plus_pose), 1e-9);
    EXPECT_LT(test::relativeError(lin.J_quadric, J_quadric * plus_quadric), 1e-9);

    // Central differences: the camera perturbed as T exp(d^), the landmark through its manifold.
    const Eigen::MatrixXd numeric_camera = test::numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          return linearizeObservation(z, plus(T_map_camera, d), landmark).residual;
        },
        6);
    const Eigen::MatrixXd numeric_quadric = test::numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          std::array<double, kQuadricParameterSize> moved;
          quadric_manifold.Plus(quadric.data(), d.data(), moved.data());
          const double* moved_blocks[2] = {pose.data(), moved.data()};
          Eigen::VectorXd r(k);
          cost.Evaluate(moved_blocks, r.data(), nullptr);
          return r;
        },
        k);
    EXPECT_LT(test::relativeError(lin.J_camera, numeric_camera), 1e-6);
    EXPECT_LT(test::relativeError(lin.J_quadric, numeric_quadric), 1e-6);
  }
}

TEST(ObservationLinearization, PlaneMatchesCostAndDifferences) {
  expectLinearizationMatchesCostAndDifferences(QuadricClass::kPlane, 11);
}
TEST(ObservationLinearization, SphereMatchesCostAndDifferences) {
  expectLinearizationMatchesCostAndDifferences(QuadricClass::kSphere, 12);
}
TEST(ObservationLinearization, CylinderMatchesCostAndDifferences) {
  expectLinearizationMatchesCostAndDifferences(QuadricClass::kCylinder, 13);
}
TEST(ObservationLinearization, ConeMatchesCostAndDifferences) {
  expectLinearizationMatchesCostAndDifferences(QuadricClass::kCone, 14);
}
TEST(ObservationLinearization, GeneralMatchesCostAndDifferences) {
  expectLinearizationMatchesCostAndDifferences(QuadricClass::kGeneral, 15);
}

TEST(ObservationLinearization, RejectsDifferentClasses) {
  std::mt19937 rng(16);
  const QuadricModel plane = test::randomQuadric(QuadricClass::kPlane, rng);
  const QuadricModel sphere = test::randomQuadric(QuadricClass::kSphere, rng);
  EXPECT_THROW(linearizeObservation(plane, Eigen::Isometry3d::Identity(), sphere),
               std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
