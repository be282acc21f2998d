#include "quadric_slam/odometry/alignment_choice.h"

namespace quadric_slam {
namespace {

bool isLost(const PointToPlaneIcp::Result& r) {
  return r.status == TrackingStatus::kLost;
}

}  // namespace

bool betterAlignment(const PointToPlaneIcp::Result& a, const PointToPlaneIcp::Result& b) {
  if (isLost(a) != isLost(b))
    return isLost(b);
  if (a.correspondences > 1.02 * b.correspondences)
    return true;
  if (b.correspondences > 1.02 * a.correspondences)
    return false;
  return a.rms_residual < b.rms_residual;
}

bool guessAlignmentReplaces(const PointToPlaneIcp::Result& from_guess,
                            const PointToPlaneIcp::Result& from_prior) {
  if (!betterAlignment(from_guess, from_prior))
    return false;
  if (from_guess.status == TrackingStatus::kOk || isLost(from_prior))
    return true;
  if (from_guess.constrained_dof > from_prior.constrained_dof)
    return true;
  return from_guess.constrained_dof + 1 >= from_prior.constrained_dof &&
         from_guess.correspondences >
             (1.0 + kGuessExtraCorrespondences) * from_prior.correspondences;
}

bool betterPhotometricMatch(const PhotometricRefinement::Result& a,
                            const PhotometricRefinement::Result& b) {
  if (a.points < kPhotometricMinPointShare * b.points)
    return false;
  if (b.points < kPhotometricMinPointShare * a.points)
    return true;
  return a.rms_after < b.rms_after;
}

Eigen::Isometry3d priorAlongFreeDirections(const Eigen::Isometry3d& aligned,
                                           const Eigen::Isometry3d& prior,
                                           const Eigen::Matrix<double, 6, Eigen::Dynamic>& free) {
  // aligned = retractLeft(xi, prior): xi = (the translation, the rotation vector) of
  // aligned * prior^-1.
  const Eigen::Isometry3d difference = aligned * prior.inverse();
  Vector6d xi;
  xi.head<3>() = difference.translation();
  xi.tail<3>() = logSO3(difference.linear());
  const Vector6d constrained = xi - free * (free.transpose() * xi);
  return pose_math::orthonormalized(pose_math::retractLeft(constrained, prior));
}

}  // namespace quadric_slam
