#include "quadric_slam/sim/trajectory_jump.h"

#include <cmath>
#include <stdexcept>

namespace quadric_slam {

Trajectory withJump(const Trajectory& trajectory, double from_stamp,
                    const Eigen::Isometry3d& T_moved_world) {
  Trajectory out = trajectory;
  for (StampedPose& pose : out)
    if (pose.stamp >= from_stamp)
      pose.T_world_sensor = T_moved_world * pose.T_world_sensor;
  return out;
}

Eigen::Isometry3d turnAbout(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                            double angle) {
  if (!axis.allFinite() || axis.norm() < 1e-12 || !std::isfinite(angle))
    throw std::invalid_argument("turnAbout: the axis must be finite and nonzero, the angle finite");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
  T.translation() = centre - T.linear() * centre;  // the centre stays where it is
  return T;
}

}  // namespace quadric_slam
