// Checking a Ceres cost function on manifolds in the mapping tests: its residual at given blocks,
// and its analytic Jacobians (ambient Jacobian x PlusJacobian) against central differences through
// Plus, per block.
#pragma once

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "../test_support.h"

namespace quadric_slam {
namespace test {

inline Eigen::VectorXd evaluate(const ceres::CostFunction& cost,
                                const std::vector<const double*>& blocks) {
  Eigen::VectorXd r(cost.num_residuals());
  cost.Evaluate(blocks.data(), r.data(), nullptr);
  return r;
}

// `context` prefixes the failure messages (e.g. the trial).
inline void expectCostJacobians(const ceres::CostFunction& cost, const std::vector<double*>& blocks,
                                const std::vector<const ceres::Manifold*>& manifolds,
                                const std::string& context = "") {
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const int m = cost.num_residuals();
  std::vector<RowMajor> jac;
  std::vector<double*> jac_ptrs;
  for (size_t b = 0; b < blocks.size(); ++b)
    jac.emplace_back(m, cost.parameter_block_sizes()[b]);
  for (auto& j : jac)
    jac_ptrs.push_back(j.data());
  Eigen::VectorXd r(m);
  ASSERT_TRUE(cost.Evaluate(blocks.data(), r.data(), jac_ptrs.data())) << context;
  for (size_t b = 0; b < blocks.size(); ++b) {
    const ceres::Manifold& man = *manifolds[b];
    const int n = man.AmbientSize(), k = man.TangentSize();
    RowMajor plus_j(n, k);
    man.PlusJacobian(blocks[b], plus_j.data());
    const Eigen::MatrixXd analytic = jac[b] * plus_j;
    const Eigen::MatrixXd numeric = numericJacobian(
        [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
          std::vector<double> moved(n);
          man.Plus(blocks[b], d.data(), moved.data());
          std::vector<const double*> args(blocks.begin(), blocks.end());
          args[b] = moved.data();
          return evaluate(cost, args);
        },
        k);
    EXPECT_LT(relativeError(analytic, numeric), 1e-6) << context << "block " << b << "\nanalytic\n"
                                                      << analytic << "\nnumeric\n"
                                                      << numeric;
  }
}

}  // namespace test
}  // namespace quadric_slam
