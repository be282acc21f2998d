#include "quadric_slam/frontend/minimal_shapes.h"

#include <Eigen/Dense>
#include <algorithm>

namespace quadric_slam {

namespace {

// The midpoint of the closest approach of the lines a + t u and b + s v (u, v unit); none when
// they are (nearly) parallel.
std::optional<Eigen::Vector3d> closestApproach(const Eigen::Vector3d& a, const Eigen::Vector3d& u,
                                               const Eigen::Vector3d& b, const Eigen::Vector3d& v) {
  const Eigen::Vector3d w = a - b;
  const double c = u.dot(v), d = u.dot(w), e = v.dot(w);
  const double denom = 1.0 - c * c;
  if (denom < 1e-6)
    return std::nullopt;
  const double t = (c * e - d) / denom, s = (e - c * d) / denom;
  return Eigen::Vector3d(0.5 * (a + t * u + b + s * v));
}

}  // namespace

// The plane through three points.
std::optional<PrimitiveShape> planeThrough(const OrientedPoint* s) {
  const Eigen::Vector3d n = (s[1].p - s[0].p).cross(s[2].p - s[0].p);
  if (n.norm() < 1e-12)
    return std::nullopt;
  const Eigen::Vector3d unit = n.normalized();
  return PrimitiveShape::plane(unit, unit.dot(s[0].p));
}

// The sphere whose centre lies on both points' normal lines (their closest approach).
std::optional<PrimitiveShape> sphereThrough(const OrientedPoint* s) {
  const std::optional<Eigen::Vector3d> centre = closestApproach(s[0].p, s[0].n, s[1].p, s[1].n);
  if (!centre)
    return std::nullopt;
  const double radius = 0.5 * ((s[0].p - *centre).norm() + (s[1].p - *centre).norm());
  return PrimitiveShape::sphere(*centre, radius);
}

// The cylinder whose axis is perpendicular to both normals and meets both normal lines (in the
// plane across the axis, where they intersect).
std::optional<PrimitiveShape> cylinderThrough(const OrientedPoint* s) {
  const Eigen::Vector3d cross = s[0].n.cross(s[1].n);
  if (cross.norm() < 1e-3)
    return std::nullopt;
  const Eigen::Vector3d axis = cross.normalized();
  const auto across = [&](const Eigen::Vector3d& v) -> Eigen::Vector3d {
    return v - axis.dot(v) * axis;
  };
  const Eigen::Vector3d q0 = across(s[0].p), q1 = across(s[1].p);
  const std::optional<Eigen::Vector3d> centre =
      closestApproach(q0, across(s[0].n).normalized(), q1, across(s[1].n).normalized());
  if (!centre)
    return std::nullopt;
  const double radius = 0.5 * ((q0 - *centre).norm() + (q1 - *centre).norm());
  return PrimitiveShape::cylinder(*centre, axis, radius);
}

// The cone tangent to the three points' planes: the apex where the three tangent planes meet; the
// unit directions from the apex to the points make one angle with the axis, which is therefore
// normal to the plane through their tips. The axis points into the opening (towards the points).
std::optional<PrimitiveShape> coneThrough(const OrientedPoint* s) {
  Eigen::Matrix3d normals;
  normals << s[0].n.transpose(), s[1].n.transpose(), s[2].n.transpose();
  const Eigen::Vector3d offsets(s[0].n.dot(s[0].p), s[1].n.dot(s[1].p), s[2].n.dot(s[2].p));
  if (std::abs(normals.determinant()) < 1e-6)
    return std::nullopt;
  const Eigen::Vector3d apex = normals.partialPivLu().solve(offsets);
  Eigen::Vector3d tips[3];
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = s[k].p - apex;
    if (v.norm() < 1e-9)
      return std::nullopt;
    tips[k] = v.normalized();
  }
  Eigen::Vector3d axis = (tips[1] - tips[0]).cross(tips[2] - tips[0]);
  if (axis.norm() < 1e-9)
    return std::nullopt;
  axis.normalize();
  if (axis.dot(tips[0] + tips[1] + tips[2]) < 0)
    axis = -axis;
  const double half_angle = std::acos(std::clamp(axis.dot(tips[0]), -1.0, 1.0));
  if (!(half_angle > 0 && half_angle < M_PI / 2))
    return std::nullopt;
  return PrimitiveShape::cone(apex, axis, half_angle);
}

}  // namespace quadric_slam
