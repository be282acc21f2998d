// Axis-aligned boxes of supporting points in a quadric frame (the observations' and landmarks'
// `extent_min`/`extent_max`), moved between frames and tested for overlap. A box is stored as its
// two corners; moving it into another frame takes the axis-aligned box of its 8 moved corners (a
// superset of the moved box, so overlap tests stay conservative).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace quadric_slam {

struct ExtentBox {
  Eigen::Vector3d min = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d max = Eigen::Vector3d::Zero();  // m

  // A box is known when its corners are finite, max >= min on every axis and it is not the
  // all-zero default (front-ends that do not fill extents leave zeros).
  bool known() const;
  // The axis-aligned box, in frame a, of this box's corners moved by T_a_b (this box in frame b).
  ExtentBox transformed(const Eigen::Isometry3d& T_a_b) const;
  // True when the boxes, each grown by `margin` (m, >= 0) on every side, intersect. Unknown boxes
  // always overlap (no evidence against a match).
  bool overlaps(const ExtentBox& other, double margin) const;
  // Smallest box holding both (an unknown box contributes nothing).
  ExtentBox merged(const ExtentBox& other) const;
};

}  // namespace quadric_slam
