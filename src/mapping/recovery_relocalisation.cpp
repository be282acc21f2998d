#include "quadric_slam/mapping/recovery_relocalisation.h"

#include <chrono>

namespace quadric_slam {
namespace {

// A third of the association gate's floors (about 10 cm / 3 deg): nearer than this, the
// odometry's pose associates as well as the relocalised one.
constexpr double kReanchorTranslation = 0.03;  // m
constexpr double kReanchorRotation = 0.02;     // rad

}  // namespace

RecoveryRelocalisation relocaliseWhileRecovering(
    TrackingRecovery* recovery, QuadricMapper* mapper,
    const std::vector<QuadricMeasurement>& observations, const Eigen::Isometry3d& T_odom_camera,
    const Eigen::Isometry3d& T_map_odom) {
  RecoveryRelocalisation out;
  if (!recovery->recovering() || recovery->poseVerified())
    return out;
  const auto start = std::chrono::steady_clock::now();
  out.attempted = true;
  out.result = recovery->relocaliser().relocalise(observations, mapper->map().landmarks());
  if (out.result.found) {
    const Eigen::Isometry3d odometry_pose = T_map_odom * T_odom_camera;
    const Eigen::Isometry3d difference = odometry_pose.inverse() * out.result.T_map_camera;
    out.reanchored = difference.translation().norm() > kReanchorTranslation ||
                     Eigen::AngleAxisd(difference.linear()).angle() > kReanchorRotation;
    if (out.reanchored)
      mapper->relocalise(Eigen::Isometry3d(out.result.T_map_camera * T_odom_camera.inverse()));
  }
  recovery->relocalisationAttempted(out.result.found, out.reanchored);
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

MapUpdate takeTrackingLoss(TrackingRecovery* recovery, QuadricMapper* mapper) {
  const TrackingRecovery::Params& params = recovery->params();
  MapUpdate promotion;
  if (!recovery->recovering() && params.promote_on_loss_min_observations > 0 &&
      static_cast<int>(mapper->map().landmarks().size()) < params.min_map_landmarks)
    promotion = mapper->promoteObservedCandidates(params.promote_on_loss_min_observations);
  recovery->trackingLost(static_cast<int>(mapper->map().landmarks().size()),
                         !promotion.promoted.empty());
  return promotion;
}

}  // namespace quadric_slam
