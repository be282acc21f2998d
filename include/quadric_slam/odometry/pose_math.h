// The odometry's pose helpers on top of the Lie-group tools of geometry/se3.h (skew, exp, adjoint
// live there): its Gauss-Newton retraction, rotation repair, angle and motion scaling. Twists are
// ordered xi = (v, omega): translation first, rotation second (se3.h's [rho; phi], and the order
// of nav_msgs covariances).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "quadric_slam/geometry/se3.h"

namespace quadric_slam {
namespace pose_math {

// Left retraction T <- [exp(omega^), v] * T used by the Gauss-Newton update; to first order it is
// the left perturbation exp(xi^) T, so covariances of xi are those of a left perturbation.
inline Eigen::Isometry3d retractLeft(const Vector6d& xi, const Eigen::Isometry3d& T) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = expSO3(xi.tail<3>());
  delta.translation() = xi.head<3>();
  return delta * T;
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
