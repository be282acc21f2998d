#include "quadric_slam/mapping/extent_box.h"

#include <limits>

namespace quadric_slam {

bool ExtentBox::known() const {
  if (!min.allFinite() || !max.allFinite())
    return false;
  if ((max - min).minCoeff() < 0.0)
    return false;
  return !(min.isZero(0.0) && max.isZero(0.0));
}

ExtentBox ExtentBox::transformed(const Eigen::Isometry3d& T_a_b) const {
  if (!known())
    return *this;
  ExtentBox out;
  out.min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  out.max = -out.min;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p_b((corner & 1) ? max.x() : min.x(), (corner & 2) ? max.y() : min.y(),
                              (corner & 4) ? max.z() : min.z());
    const Eigen::Vector3d p_a = T_a_b * p_b;
    out.min = out.min.cwiseMin(p_a);
    out.max = out.max.cwiseMax(p_a);
  }
  return out;
}

bool ExtentBox::overlaps(const ExtentBox& other, double margin) const {
  if (!known() || !other.known())
    return true;
  for (int i = 0; i < 3; ++i) {
    if (min[i] - margin > other.max[i] + margin || other.min[i] - margin > max[i] + margin)
      return false;
  }
  return true;
}

ExtentBox ExtentBox::merged(const ExtentBox& other) const {
  if (!known())
    return other;
  if (!other.known())
    return *this;
  ExtentBox out;
  out.min = min.cwiseMin(other.min);
  out.max = max.cwiseMax(other.max);
  return out;
}

}  // namespace quadric_slam
