// A quadric landmark of the map (the core twin of msg/Quadric.msg).
#pragma once

#include <Eigen/Core>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

struct QuadricLandmark {
  int id = 0;
  QuadricModel quadric_map;    // T_map_quadric, S, sigma, class
  int observations = 0;        // frames that observed it
  Eigen::MatrixXd covariance;  // k x k marginal covariance in the class's minimal space, or empty
  double last_observed = 0.0;  // stamp of the latest observing frame (s)
  Eigen::Vector3d extent_min =
      Eigen::Vector3d::Zero();  // box of observed points, quadric frame (m)
  Eigen::Vector3d extent_max = Eigen::Vector3d::Zero();
};

}  // namespace quadric_slam
