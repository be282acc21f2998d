// A marginalisation prior: what is left of the factors of variables that were eliminated from the
// sliding window, as one linear(ised) factor on the variables that stay (OKVIS, VINS-Mono).
//
// Eliminating variables m from the Gauss-Newton system of the factors that touch them,
//   [H_mm H_mr; H_rm H_rr] [dm; dr] = -[g_m; g_r]   (H = A^T A, g = A^T r at the estimate x0),
// leaves the Schur complement on the kept variables r:
//   H* = H_rr - H_rm H_mm^-1 H_mr,   g* = g_r - H_rm H_mm^-1 g_m,
// the exact marginal of the linearised problem. It is stored as a residual
//   e(x) = r0 + J (x [-] x0)   with J^T J = H*, J^T r0 = g*
// (H* = V S V^T, J = S^1/2 V^T, r0 = S^-1/2 V^T g*, directions with S below a relative threshold
// dropped: they carry no information), so 1/2 |e|^2 has the same gradient and Hessian at x0 as the
// eliminated factors. x [-] x0 is the Minus of each variable's manifold (geometry/manifolds.h):
// the body-frame log of T_x0^-1 T_x for poses, the class's minimal vector B^+ [log; ds] for
// quadrics, so the prior lives in the same tangent spaces as the window's solver. J stays at the
// linearisation point (the eliminated factors cannot be relinearised); the Jacobian of e in the
// ambient block is J_i d(x_i [-] x0_i)/dx_i, exact for the manifold Minus (see
// LinearizedPriorCost).
#pragma once

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <array>
#include <vector>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/geometry/quadric_class.h"

namespace quadric_slam {

// One variable of a prior: a keyframe pose (id = the keyframe's frame index) or a landmark
// (id = landmark id, with its class), and its value at the linearisation point.
struct PriorVariable {
  enum class Kind { kPose, kLandmark };
  Kind kind = Kind::kPose;
  int id = 0;
  QuadricClass quadric_class = QuadricClass::kPlane;  // landmarks only
  std::array<double, kQuadricParameterSize> x0{};     // ambient; poses use the first 7

  int ambientSize() const { return kind == Kind::kPose ? kPoseParameterSize : kQuadricParameterSize; }
  int tangentSize() const;
  bool operator==(const PriorVariable& o) const { return kind == o.kind && id == o.id; }
};

struct LinearizedPrior {
  std::vector<PriorVariable> variables;  // column blocks of J, in order
  Eigen::MatrixXd J;                     // rows x sum of tangent sizes
  Eigen::VectorXd r0;                    // rows

  bool empty() const { return variables.empty() || J.rows() == 0; }
  int tangentSize() const;
  // Column offset of variable i in J.
  int offset(std::size_t i) const;
  // Index of the variable, or -1.
  int find(PriorVariable::Kind kind, int id) const;
};

// The prior on `variables` (tangent sizes summing to H.rows()) from the information H and gradient
// g of the linearised factors, after eliminating the columns flagged in `eliminate` (one flag per
// variable): the Schur complement above. Returns an empty prior when nothing is kept or no
// direction has information. relative_threshold: eigenvalues of H* below this times the largest
// are dropped (> 0).
LinearizedPrior schurComplementPrior(const std::vector<PriorVariable>& variables,
                                     const std::vector<bool>& eliminate, const Eigen::MatrixXd& H,
                                     const Eigen::VectorXd& g, double relative_threshold = 1e-10);

// The same prior with variable `index` eliminated (its information folded into the others).
LinearizedPrior eliminateVariable(const LinearizedPrior& prior, std::size_t index);

// x [-] x0 of a prior variable at the ambient value x, and its Jacobian d/dx (tangent x ambient).
Eigen::VectorXd priorVariableMinus(const PriorVariable& variable, const double* x);
Eigen::MatrixXd priorVariableMinusJacobian(const PriorVariable& variable, const double* x);

// e(x) = r0 + J (x [-] x0); one parameter block per prior variable, in order (7 for poses, 10
// for landmarks, with the PoseManifold / QuadricManifold of the class set on them).
class LinearizedPriorCost : public ceres::CostFunction {
 public:
  explicit LinearizedPriorCost(LinearizedPrior prior);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  const LinearizedPrior& prior() const { return prior_; }

 private:
  LinearizedPrior prior_;
};

}  // namespace quadric_slam
