#include "quadric_slam/ros/odometry_status.h"

namespace quadric_slam {

void markLost(nav_msgs::Odometry& odom) {
  for (int i = 0; i < 36; ++i)
    odom.pose.covariance[i] = i % 7 == 0 ? kLostPoseVariance : 0.0;
}

bool isLost(const nav_msgs::Odometry& odom) {
  for (int i = 0; i < 6; ++i) {
    if (!(odom.pose.covariance[7 * i] >= kLostPoseVariance))
      return false;
  }
  return true;
}

}  // namespace quadric_slam
