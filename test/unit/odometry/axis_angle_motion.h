// A camera motion written as the tests think of it: a translation and a turn about an axis.
#pragma once

#include <Eigen/Geometry>
#include <cmath>

namespace quadric_slam {
namespace test {

// T = [R(axis, degrees), translation] (the axis need not be unit).
inline Eigen::Isometry3d motion(const Eigen::Vector3d& translation, const Eigen::Vector3d& axis,
                                double degrees) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(degrees * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  T.translation() = translation;
  return T;
}

}  // namespace test
}  // namespace quadric_slam
