// The marginalisation prior (mapping/linearized_prior.h): the Schur complement of a linear least
// squares problem keeps the kept variables' solution and information exactly; the prior factor's
// Jacobian, through the manifolds' Plus, against central differences away from its linearisation
// point, for a pose and landmarks of every class.
#include <gtest/gtest.h>

#include <ceres/manifold.h>

#include <random>

#include "../test_support.h"
#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/linearized_prior.h"

namespace quadric_slam {
namespace {

PriorVariable poseVariable(int id, const Eigen::Isometry3d& T) {
  PriorVariable v;
  v.kind = PriorVariable::Kind::kPose;
  v.id = id;
  poseToParameters(T, v.x0.data());
  return v;
}

PriorVariable landmarkVariable(int id, const QuadricModel& q) {
  PriorVariable v;
  v.kind = PriorVariable::Kind::kLandmark;
  v.id = id;
  v.quadric_class = q.quadricClass();
  quadricToParameters(q, v.x0.data());
  return v;
}

// A linear problem min |A x + r|^2 over blocks of 6, 3, 6 and 4 columns (the tangent sizes of a
// pose, a plane, a cone and a sphere); eliminate the first two blocks.
TEST(LinearizedPrior, SchurComplementKeepsTheKeptSolutionAndInformation) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const std::vector<PriorVariable> variables = {
      poseVariable(1, Eigen::Isometry3d::Identity()),
      landmarkVariable(2, test::randomQuadric(QuadricClass::kPlane, rng)),
      landmarkVariable(3, test::randomQuadric(QuadricClass::kCone, rng)),
      landmarkVariable(4, test::randomQuadric(QuadricClass::kSphere, rng))};
  const int n = 6 + 3 + 6 + 4, m = 30;
  ASSERT_EQ(variables[2].tangentSize(), 6);
  Eigen::MatrixXd A(m, n);
  Eigen::VectorXd r(m);
  for (int i = 0; i < m; ++i) {
    r[i] = gauss(rng);
    for (int j = 0; j < n; ++j)
      A(i, j) = gauss(rng);
  }
  const Eigen::MatrixXd H = A.transpose() * A;
  const Eigen::VectorXd g = A.transpose() * r;
  const LinearizedPrior prior =
      schurComplementPrior(variables, {true, true, false, false}, H, g);
  ASSERT_EQ(prior.variables.size(), 2u);
  EXPECT_EQ(prior.variables[0].id, 3);
  EXPECT_EQ(prior.variables[1].id, 4);
  ASSERT_EQ(prior.J.cols(), 10);
  ASSERT_EQ(prior.J.rows(), 10);  // full rank: every kept direction has information

  // The full solution's kept part equals the minimiser of the prior alone.
  const Eigen::VectorXd full = -H.ldlt().solve(g);
  const Eigen::VectorXd from_prior =
      -(prior.J.transpose() * prior.J).ldlt().solve(prior.J.transpose() * prior.r0);
  EXPECT_LT((full.tail(10) - from_prior).norm(), 1e-9 * std::max(1.0, full.norm()));
  // The kept marginal covariance is the same: (H^-1)_rr = (J^T J)^-1.
  const Eigen::MatrixXd full_covariance = H.inverse().bottomRightCorner(10, 10);
  const Eigen::MatrixXd prior_covariance = (prior.J.transpose() * prior.J).inverse();
  EXPECT_LT(test::relativeError(full_covariance, prior_covariance), 1e-9);

  // Eliminating one more variable from the prior is the Schur complement of the whole problem.
  const LinearizedPrior only_sphere = eliminateVariable(prior, 0);
  ASSERT_EQ(only_sphere.variables.size(), 1u);
  EXPECT_EQ(only_sphere.variables[0].id, 4);
  const Eigen::VectorXd sphere_only =
      -(only_sphere.J.transpose() * only_sphere.J)
           .ldlt()
           .solve(only_sphere.J.transpose() * only_sphere.r0);
  EXPECT_LT((full.tail(4) - sphere_only).norm(), 1e-9 * std::max(1.0, full.norm()));

  // A direction without information is dropped, not inverted.
  Eigen::MatrixXd A_deficient = A;
  A_deficient.col(n - 1).setZero();
  const LinearizedPrior deficient = schurComplementPrior(
      variables, {true, true, false, false}, A_deficient.transpose() * A_deficient,
      A_deficient.transpose() * r);
  EXPECT_EQ(deficient.J.rows(), 9);
  EXPECT_LT(deficient.J.col(9).norm(), 1e-9);
  EXPECT_TRUE(schurComplementPrior(variables, {true, true, true, true}, H, g).empty());
  EXPECT_THROW(schurComplementPrior(variables, {true, false}, H, g), std::invalid_argument);
}

// e(x) = r0 + J (x [-] x0) evaluated away from x0; the Ceres-visible tangent Jacobian (ambient
// Jacobian times the manifold's PlusJacobian) against central differences through the manifold's
// Plus.
TEST(LinearizedPrior, CostJacobianMatchesNumericDifferentiation) {
  std::mt19937 rng(11);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<PriorVariable> variables = {poseVariable(5, test::randomPose(rng))};
  int id = 10;
  for (QuadricClass c : {QuadricClass::kPlane, QuadricClass::kSphere, QuadricClass::kCylinder,
                         QuadricClass::kCone, QuadricClass::kGeneral})
    variables.push_back(landmarkVariable(id++, test::randomQuadric(c, rng)));
  LinearizedPrior prior;
  prior.variables = variables;
  const int n = prior.tangentSize();
  prior.J = Eigen::MatrixXd(n + 3, n);
  prior.r0 = Eigen::VectorXd(n + 3);
  for (int i = 0; i < prior.J.rows(); ++i) {
    prior.r0[i] = gauss(rng);
    for (int j = 0; j < n; ++j)
      prior.J(i, j) = gauss(rng);
  }
  const LinearizedPriorCost cost(prior);
  ASSERT_EQ(cost.num_residuals(), n + 3);

  // Manifolds and the evaluation point: each variable moved off x0 by a sizeable tangent step
  // (0.3 rad, 0.3 m), where J_r^-1 differs clearly from the identity.
  std::vector<std::unique_ptr<ceres::Manifold>> manifolds;
  std::vector<std::vector<double>> x;
  for (const PriorVariable& v : variables) {
    if (v.kind == PriorVariable::Kind::kPose)
      manifolds.push_back(std::make_unique<PoseManifold>());
    else
      manifolds.push_back(std::make_unique<QuadricManifold>(v.quadric_class));
    Eigen::VectorXd step(v.tangentSize());
    for (int j = 0; j < step.size(); ++j)
      step[j] = 0.3 * gauss(rng) / std::sqrt(3.0);
    std::vector<double> xi(v.ambientSize());
    manifolds.back()->Plus(v.x0.data(), step.data(), xi.data());
    x.push_back(xi);
  }

  auto evaluate = [&](const std::vector<std::vector<double>>& at) {
    std::vector<const double*> parameters;
    for (const auto& xi : at)
      parameters.push_back(xi.data());
    Eigen::VectorXd e(cost.num_residuals());
    EXPECT_TRUE(cost.Evaluate(parameters.data(), e.data(), nullptr));
    return e;
  };
  // At x0 the residual is r0.
  std::vector<std::vector<double>> at_x0;
  for (const PriorVariable& v : variables)
    at_x0.emplace_back(v.x0.begin(), v.x0.begin() + v.ambientSize());
  EXPECT_LT((evaluate(at_x0) - prior.r0).norm(), 1e-12);

  std::vector<const double*> parameters;
  for (const auto& xi : x)
    parameters.push_back(xi.data());
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> ambient;
  std::vector<double*> jacobians;
  for (const PriorVariable& v : variables) {
    ambient.emplace_back(cost.num_residuals(), v.ambientSize());
    jacobians.push_back(ambient.back().data());
  }
  Eigen::VectorXd e(cost.num_residuals());
  ASSERT_TRUE(cost.Evaluate(parameters.data(), e.data(), jacobians.data()));
  for (std::size_t i = 0; i < variables.size(); ++i) {
    const int k = variables[i].tangentSize();
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> plus_jacobian(
        variables[i].ambientSize(), k);
    manifolds[i]->PlusJacobian(x[i].data(), plus_jacobian.data());
    const Eigen::MatrixXd analytic = ambient[i] * plus_jacobian;
    const Eigen::MatrixXd numeric = test::numericJacobian(
        [&](const Eigen::VectorXd& d) {
          std::vector<std::vector<double>> moved = x;
          manifolds[i]->Plus(x[i].data(), d.data(), moved[i].data());
          return evaluate(moved);
        },
        k);
    EXPECT_LT(test::relativeError(analytic, numeric), 1e-6) << "variable " << i;
    // Away from x0 the pose's Jacobian is not J itself (J_r^-1 of the error): the check above
    // would notice a Minus Jacobian taken at x0 instead of x. (A sphere's translation-only
    // tangent has J_r^-1 = I in its directions.)
    if (i == 0) {
      EXPECT_GT(test::relativeError(analytic, prior.J.middleCols(prior.offset(i), k)), 1e-3);
    }
  }
}

}  // namespace
}  // namespace quadric_slam
