// A camera carried somewhere else while it saw nothing (a covered lens, a gap in a recording):
// the poses of a trajectory from a stamp on, moved by a rigid motion of the world. With the motion
// a turn about a vertical line through the centre of interest, the camera keeps looking at what it
// looked at, from elsewhere on its arc (a turn of angle a at horizontal distance r moves it by the
// chord 2 r sin(a / 2) and turns its view by a).
#pragma once

#include <Eigen/Geometry>

#include "quadric_slam/io/trajectory_io.h"

namespace quadric_slam {

// T_moved_world applied to every pose with stamp >= from_stamp: T_world_sensor' = T_moved_world
// T_world_sensor; earlier poses unchanged.
Trajectory withJump(const Trajectory& trajectory, double from_stamp,
                    const Eigen::Isometry3d& T_moved_world);

// The rigid motion turning the world by `angle` (rad, right-handed) about the line through
// `centre` along `axis` (nonzero; normalised). Throws std::invalid_argument for a zero or
// non-finite axis.
Eigen::Isometry3d turnAbout(const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
                            double angle);

}  // namespace quadric_slam
