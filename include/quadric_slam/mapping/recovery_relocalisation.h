// One recovering frame's relocalisation, as QuadricSlam and the mapping nodelet run it just before
// the frame goes to the mapper (mapping/tracking_recovery.h). While the map waits to be anchored
// again and the relocaliser has not yet confirmed the pose, the frame's observations are matched
// against the map's landmarks with no pose prior (mapping/relocaliser.h). When the relocalised pose
// is away from where the odometry puts the camera (T_map_odom T_odom_camera) by more than a third
// of the association gate (the odometry's pose would still associate, and re-anchoring would only
// cut the odometry chain), the mapper is re-anchored there (QuadricMapper::relocalise): this frame
// is then associated from the relocalised pose, and TrackingRecovery's anchoring and confirmation
// decide, as after any loss, when mapping resumes.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/relocaliser.h"
#include "quadric_slam/mapping/tracking_recovery.h"

namespace quadric_slam {

struct RecoveryRelocalisation {
  bool attempted = false;   // the frame needed a relocalisation and the relocaliser ran
  bool reanchored = false;  // the mapper was re-anchored at result.T_map_camera
  Relocalisation result;
  double seconds = 0.0;  // wall time of the attempt
};

// T_map_odom: the mapper's current correction (its latest MapperFrameResult::T_map_odom).
RecoveryRelocalisation relocaliseWhileRecovering(
    TrackingRecovery* recovery, QuadricMapper* mapper,
    const std::vector<QuadricMeasurement>& observations, const Eigen::Isometry3d& T_odom_camera,
    const Eigen::Isometry3d& T_map_odom);

// A loss of tracking as the map takes it, in QuadricSlam and the mapping nodelet: when the map
// holds fewer landmarks than the recovery needs to anchor against, the candidates seen often
// enough become landmarks first (TrackingRecovery::Params::promote_on_loss_min_observations);
// then the recovery starts (TrackingRecovery::trackingLost). Returns that promotion (empty when
// none), whose observations a BatchRecorder records.
MapUpdate takeTrackingLoss(TrackingRecovery* recovery, QuadricMapper* mapper);

}  // namespace quadric_slam
