#include "quadric_slam/odometry/constrained_directions.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>

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
  Q_ = Matrix6d::Identity();
  H_complement_inverse_.setZero();
  if (!(lambda(5) > 0) || !H.allFinite()) {
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
  mu_ = general.eigenvalues();
  constrained_ = 0;
  for (int i = 0; i < 6; ++i)
    constrained_ += mu_(i) > 1.0 ? 1 : 0;
  const int free = 6 - constrained_;
  if (free > 0 && constrained_ > 0) {
    // A full QR of the unconstrained eigenvectors: its first columns span them, the rest is the
    // orthogonal complement.
    const Eigen::Matrix<double, 6, Eigen::Dynamic> unconstrained =
        general.eigenvectors().leftCols(free);
    Q_ = Eigen::HouseholderQR<Eigen::Matrix<double, 6, Eigen::Dynamic>>(unconstrained)
             .householderQ();
  }
  if (constrained_ > 0) {
    const Eigen::MatrixXd complement = Q_.rightCols(constrained_);
    const Eigen::MatrixXd restricted = complement.transpose() * H * complement;
    H_complement_inverse_.topLeftCorner(constrained_, constrained_) =
        restricted.ldlt().solve(Eigen::MatrixXd::Identity(constrained_, constrained_));
  }
}

Vector6d ConstrainedDirections::step(const Vector6d& b) const {
  if (constrained_ == 0)
    return Vector6d::Zero();
  // delta = -Q_c (Q_c^T H Q_c)^-1 Q_c^T b: Gauss-Newton on the complement Q_c.
  const Eigen::MatrixXd complement = Q_.rightCols(constrained_);
  const Eigen::VectorXd reduced = complement.transpose() * b;
  return -complement * (H_complement_inverse_.topLeftCorner(constrained_, constrained_) * reduced);
}

Matrix6d ConstrainedDirections::covariance(double sigma2, double degenerate_variance) const {
  Matrix6d cov = Matrix6d::Zero();
  const int free = 6 - constrained_;
  if (constrained_ > 0) {
    const Eigen::MatrixXd complement = Q_.rightCols(constrained_);
    cov += sigma2 * complement * H_complement_inverse_.topLeftCorner(constrained_, constrained_) *
           complement.transpose();
  }
  if (free > 0) {
    const Eigen::MatrixXd unconstrained = Q_.leftCols(free);
    cov += degenerate_variance * unconstrained * unconstrained.transpose();
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
