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
  complement_inverse_.setZero();
  unconstrained_projector_ = Matrix6d::Identity();
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
  // An orthonormal basis whose first columns span the unconstrained eigenvectors (a full QR of
  // them) and whose others span their orthogonal complement.
  Matrix6d Q = Matrix6d::Identity();
  if (free > 0 && constrained_ > 0) {
    const Eigen::Matrix<double, 6, Eigen::Dynamic> free_eigenvectors =
        general.eigenvectors().leftCols(free);
    Q = Eigen::HouseholderQR<Eigen::Matrix<double, 6, Eigen::Dynamic>>(free_eigenvectors)
            .householderQ();
  }
  const Eigen::MatrixXd unconstrained = Q.leftCols(free);
  unconstrained_projector_ = unconstrained * unconstrained.transpose();
  if (constrained_ > 0) {
    const Eigen::MatrixXd complement = Q.rightCols(constrained_);
    const Eigen::MatrixXd restricted = complement.transpose() * H * complement;
    complement_inverse_ =
        complement *
        restricted.ldlt().solve(Eigen::MatrixXd::Identity(constrained_, constrained_)) *
        complement.transpose();
  }
}

Vector6d ConstrainedDirections::step(const Vector6d& b) const {
  // Gauss-Newton on the complement; zero along the unconstrained directions.
  return -complement_inverse_ * b;
}

Matrix6d ConstrainedDirections::covariance(double sigma2, double degenerate_variance) const {
  const Matrix6d cov =
      sigma2 * complement_inverse_ + degenerate_variance * unconstrained_projector_;
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
