// One quadric observation linearised at given estimates: the unwhitened residual of
// QuadricObservationCost (eq. 22 with L = I, in the measurement's minimal coordinates) and its
// Jacobians w.r.t. the camera pose tangent [rho; phi] (k x 6, body frame) and the landmark's
// minimal tangent (k x k, Table II). Used to propagate pose and landmark uncertainty into the
// association gate and to fold a leaving keyframe's observations into landmark priors.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// k <= 9: fixed-capacity matrices (no heap; one is made for every association pair).
struct ObservationLinearization {
  Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, 9, 1> residual;             // k
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::ColMajor, 9, 6> J_camera;             // k x 6
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, 9, 9> J_quadric;  // k x k
  bool valid = false;  // false when the cost could not be evaluated (non-finite)
};

// Throws std::invalid_argument when z and the landmark are of different classes.
ObservationLinearization linearizeObservation(const QuadricModel& z_camera,
                                              const Eigen::Isometry3d& T_map_camera,
                                              const QuadricModel& landmark_map);

}  // namespace quadric_slam
