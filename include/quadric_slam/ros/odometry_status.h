// How the odometry nodelet tells its subscribers that tracking is lost. nav_msgs/Odometry has no
// status field, so a lost frame is published with the last pose (odom and tf stay continuous, as
// REP-105 asks) and every pose variance set to kLostPoseVariance (9999, the value rtabmap's
// odometry uses for the same purpose); the mapping nodelet adds nothing from such a frame
// (mapping/tracking_recovery.h). A subscriber that only reads poses sees a huge uncertainty.
#pragma once

#include <nav_msgs/Odometry.h>

namespace quadric_slam {

constexpr double kLostPoseVariance = 9999.0;  // m^2 and rad^2

// Sets the pose covariance to kLostPoseVariance on the diagonal, 0 elsewhere.
void markLost(nav_msgs::Odometry& odom);
// True when every diagonal pose variance is at least kLostPoseVariance.
bool isLost(const nav_msgs::Odometry& odom);

}  // namespace quadric_slam
