// Small SE(3) helpers for odometry: left-perturbation retraction, adjoint, motion scaling.
// Twists are ordered xi = (v, omega): translation first, rotation second (the order of
// nav_msgs covariances).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace quadric_slam {
namespace pose_math {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d m;
  m << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return m;
}

// Rotation exp(omega^) (Rodrigues), exact for any angle.
inline Eigen::Matrix3d expSo3(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12)
    return Eigen::Matrix3d::Identity() + skew(omega);
  return Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
}

// Left retraction T <- [exp(omega^), v] * T used by the Gauss-Newton update; to first order it is
// the left perturbation exp(xi^) T, so covariances of xi are those of a left perturbation.
inline Eigen::Isometry3d retractLeft(const Vector6& xi, const Eigen::Isometry3d& T) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = expSo3(xi.tail<3>());
  delta.translation() = xi.head<3>();
  return delta * T;
}

// Adjoint of T for xi = (v, omega): exp((Ad_T xi)^) = T exp(xi^) T^-1.
inline Matrix6 adjoint(const Eigen::Isometry3d& T) {
  Matrix6 ad = Matrix6::Zero();
  const Eigen::Matrix3d R = T.linear();
  ad.topLeftCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = skew(T.translation()) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

// T with its rotation replaced by the nearest rotation matrix (polar decomposition, U V^T).
// Products and Isometry inverses (which transpose) would otherwise let rounding errors grow without
// bound along a trajectory: a rotation 0.3% off orthonormal after a few hundred frames is a scale
// error.
inline Eigen::Isometry3d orthonormalized(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d out = T;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.linear(),
                                              Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {  // never for a drifted rotation, but keep it a rotation
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1;
    R = U * svd.matrixV().transpose();
  }
  out.linear() = R;
  return out;
}

// Rotation angle of T (rad, in [0, pi]).
inline double rotationAngle(const Eigen::Isometry3d& T) {
  return Eigen::AngleAxisd(T.linear()).angle();
}

// The motion T scaled by factor k (rotation angle and translation both scaled): a
// constant-velocity extrapolation over k times the interval T spans.
inline Eigen::Isometry3d scaleMotion(const Eigen::Isometry3d& T, double k) {
  const Eigen::AngleAxisd aa(T.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::AngleAxisd(aa.angle() * k, aa.axis()).toRotationMatrix();
  out.translation() = T.translation() * k;
  return out;
}

}  // namespace pose_math
}  // namespace quadric_slam
