#include "quadric_slam/odometry/constrained_directions.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace quadric_slam {

ConstrainedDirections::ConstrainedDirections(const Matrix6d& H, const Matrix6d& noise_information,
                                             double min_eigenvalue_ratio,
                                             double noise_information_factor) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> plain(H, Eigen::EigenvaluesOnly);
  const Vector6d lambda = plain.eigenvalues();  // ascending
  eigenvalue_ratio_ = lambda(5) > 0 ? std::max(0.0, lambda(0)) / lambda(5) : 0.0;
  if (!(lambda(5) > 0) || !H.allFinite()) {
    V_ = Matrix6d::Identity();
    mu_.setZero();
    constrained_ = 0;
    return;
  }
  // B = ratio * lambda_max I + factor * N is positive definite (its first term is), so the
  // generalised problem is well posed; V^T B V = I and V^T H V = diag(mu).
  Matrix6d B = Matrix6d::Identity() * (min_eigenvalue_ratio * lambda(5));
  if (noise_information_factor > 0)
    B += noise_information_factor * 0.5 * (noise_information + noise_information.transpose());
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix6d> general(H, B);
  V_ = general.eigenvectors();
  mu_ = general.eigenvalues();
  constrained_ = 0;
  for (int i = 0; i < 6; ++i)
    constrained_ += mu_(i) > 1.0 ? 1 : 0;
}

Vector6d ConstrainedDirections::step(const Vector6d& b) const {
  // H^-1 = V diag(1 / mu) V^T, restricted to the constrained directions (the last ones).
  Vector6d delta = Vector6d::Zero();
  for (int i = 6 - constrained_; i < 6; ++i)
    delta -= V_.col(i) * (V_.col(i).dot(b) / mu_(i));
  return delta;
}

Matrix6d ConstrainedDirections::covariance(double sigma2, double degenerate_variance) const {
  Matrix6d cov = Matrix6d::Zero();
  for (int i = 0; i < 6; ++i) {
    const Vector6d v = V_.col(i);
    if (i >= 6 - constrained_) {
      cov += (sigma2 / mu_(i)) * v * v.transpose();
    } else {
      const Vector6d unit = v.normalized();
      cov += degenerate_variance * unit * unit.transpose();
    }
  }
  return 0.5 * (cov + cov.transpose());
}

double ConstrainedDirections::informationOverNoise(const Matrix6d& H,
                                                   const Matrix6d& noise_information) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> noise(noise_information, Eigen::EigenvaluesOnly);
  const double largest = noise.eigenvalues()(5);
  if (!(largest > 0))
    return std::numeric_limits<double>::infinity();
  // A tiny ridge keeps B positive definite where N has no noise at all (such a direction's ratio
  // is then huge, as it should be).
  const Matrix6d B = noise_information + Matrix6d::Identity() * (1e-9 * largest);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Matrix6d> general(H, B, Eigen::EigenvaluesOnly);
  return general.eigenvalues()(0);
}

}  // namespace quadric_slam
