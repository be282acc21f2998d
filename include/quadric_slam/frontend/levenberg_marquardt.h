// The segmentation's small Levenberg-Marquardt fits (ShapeRefiner's shapes, the general quadric's
// Sampson fit): the damping, the stopping rule and the iteration.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>

namespace quadric_slam {

// The damping lambda of (H + lambda diag(H)) delta = -g for a cost |r|^2 (H = J^T J, g = J^T r),
// updated from the gain ratio after Nielsen (Madsen, Nielsen & Tingleff, "Methods for Non-Linear
// Least Squares Problems", 2004, eq. 3.16). The fits used to divide lambda by 10 after an accepted
// step and multiply it by 10 after a rejected one; on the segmentation's fits that rejected the
// first step of more than half of all iterations (lambda divided below what the next step needed,
// then raised again), a cost evaluation wasted each time.
struct LevenbergMarquardtDamping {
  explicit LevenbergMarquardtDamping(double initial_lambda) : lambda(initial_lambda) {}

  // An accepted step: the cost fell by `actual` where the linear model predicted `predicted`. A
  // gain ratio near 1 (the model holds) divides lambda by up to 3, one near 0 multiplies it by up
  // to 2.
  void accepted(double actual, double predicted) {
    const double rho = predicted > 0 ? actual / predicted : 1.0;
    lambda = std::max(kMinLambda, lambda * std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3)));
    growth = 2.0;
  }
  // A rejected step (the cost rose, or the step left the shape's class): lambda grows by 2, then 4,
  // 8, ... until a step is accepted.
  void rejected() {
    lambda *= growth;
    growth *= 2.0;
  }

  static constexpr double kMinLambda = 1e-9;
  double lambda;
  double growth = 2.0;
};

// The decrease of |r|^2 that the linear model r + J delta predicts for the step delta:
// -(2 delta^T g + delta^T H delta).
template <typename MatrixH, typename VectorG, typename VectorDelta>
double predictedDecrease(const MatrixH& H, const VectorG& g, const VectorDelta& delta) {
  return -(2.0 * delta.dot(g) + delta.dot(H * delta));
}

// Whether a step that lowered the cost (sum of squared residuals of n points, k parameters) by
// `decrease` to `cost` ends the fit: below `tolerance` residual variances (sigma^2 = cost / (n -
// k)). Being delta away from the optimum costs delta^T H delta = sigma^2 times delta's squared
// Mahalanobis distance under the fit's covariance sigma^2 H^-1: a fit converging at least linearly
// at rate 1/2 has at most about one such decrease left and stops within about sqrt(tolerance)
// standard deviations of its optimum, whatever the number of points. Not so a fit whose points
// leave a long, flat valley in its cost: a cone seen over a narrow band of its surface (25 deg, 0.1
// m) at 1 cm noise crept from a half angle of 0.3 rad to its optimum at 1.0 over 40 iterations,
// each step gaining little (the iteration limit ends such fits, as it did before this rule).
inline bool convergedWithinNoise(double decrease, double cost, int n, int k, double tolerance) {
  return decrease < tolerance * cost / std::max(1, n - k);
}

struct LevenbergMarquardtSettings {
  int max_iterations = 10;
  double relative_tolerance = 1e-6;  // stop when a step lowers the cost by less than this share
  double variance_tolerance = 0.1;   // or by less than this many residual variances
  double initial_lambda = 1e-4;
};

// Minimises the sum of squared residuals over a state with k degrees of freedom from x, for at most
// settings.max_iterations iterations with up to 10 damped steps each. residuals(state) gives the
// residual vector (n entries); normalEquations(state, r, H, g) sets H = J^T J and g = J^T r of the
// residuals' Jacobian J in the step's coordinates; step(state, delta) gives the state moved by
// delta, or none when delta leaves the state's domain (the step is then rejected). cost receives
// the returned state's sum of squared residuals.
template <typename State, typename Residuals, typename NormalEquations, typename Step>
State minimiseSquares(State x, int k, const LevenbergMarquardtSettings& settings,
                      Residuals residuals, NormalEquations normalEquations, Step step,
                      double& cost) {
  Eigen::VectorXd r = residuals(x);
  cost = r.squaredNorm();
  const int n = static_cast<int>(r.size());
  LevenbergMarquardtDamping damping(settings.initial_lambda);
  for (int it = 0; it < settings.max_iterations; ++it) {
    Eigen::MatrixXd H;
    Eigen::VectorXd g;
    normalEquations(x, r, H, g);
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Eigen::MatrixXd A = H;
      A.diagonal() += damping.lambda * H.diagonal().cwiseMax(1e-12);
      const Eigen::VectorXd delta = A.ldlt().solve(-g);
      if (!delta.allFinite())
        break;
      const std::optional<State> candidate = step(x, delta);
      if (!candidate) {
        damping.rejected();
        continue;
      }
      Eigen::VectorXd r_new = residuals(*candidate);
      const double cost_new = r_new.squaredNorm();
      if (!(std::isfinite(cost_new) && cost_new < cost)) {
        damping.rejected();
        continue;
      }
      const double decrease = cost - cost_new;
      damping.accepted(decrease, predictedDecrease(H, g, delta));
      x = *candidate;
      r.swap(r_new);
      cost = cost_new;
      improved = true;
      if (decrease < settings.relative_tolerance * (cost + decrease) ||
          convergedWithinNoise(decrease, cost, n, k, settings.variance_tolerance))
        return x;
    }
    if (!improved)
      break;
  }
  return x;
}

}  // namespace quadric_slam
