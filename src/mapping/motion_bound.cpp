#include "quadric_slam/mapping/motion_bound.h"

#include <Eigen/Eigenvalues>

namespace quadric_slam {

Matrix6d boundIncrementCovariance(const Matrix6d& covariance, double dt, double max_speed,
                                  double max_angular_speed) {
  if (!(dt > 0.0) || !(max_speed > 0.0) || !(max_angular_speed > 0.0))
    return covariance;
  Vector6d bound_sigma;
  bound_sigma << Eigen::Vector3d::Constant(max_speed * dt),
      Eigen::Vector3d::Constant(max_angular_speed * dt);
  // In the scaled coordinates the bound is the unit ball: clamp the eigenvalues there.
  const Vector6d to_scaled = bound_sigma.cwiseInverse();
  const Matrix6d scaled = to_scaled.asDiagonal() * covariance * to_scaled.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(0.5 * (scaled + scaled.transpose()));
  if (eigen.info() != Eigen::Success || eigen.eigenvalues().maxCoeff() <= 1.0)
    return covariance;
  const Vector6d clamped = eigen.eigenvalues().cwiseMin(1.0);
  const Matrix6d bounded_scaled =
      eigen.eigenvectors() * clamped.asDiagonal() * eigen.eigenvectors().transpose();
  const Matrix6d bounded =
      bound_sigma.asDiagonal() * bounded_scaled * bound_sigma.asDiagonal();
  return 0.5 * (bounded + bounded.transpose());
}

}  // namespace quadric_slam
