// Shared by the rostest checkers: a nav_msgs/Path as a trajectory for the evaluation code.
#pragma once

#include <nav_msgs/Path.h>

#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/ros/conversions.h"

namespace quadric_slam::test {

inline Trajectory toTrajectory(const nav_msgs::Path& path) {
  Trajectory out;
  for (const geometry_msgs::PoseStamped& pose : path.poses)
    out.push_back({pose.header.stamp.toSec(), fromPoseMsg(pose.pose)});
  return out;
}

}  // namespace quadric_slam::test
