#include "quadric_slam/geometry/shapes.h"

#include <cmath>
#include <stdexcept>

namespace quadric_slam {

namespace {

void requireClass(const QuadricModel& q, QuadricClass c, const char* fn) {
  if (q.quadricClass() != c)
    throw std::invalid_argument(std::string(fn) + ": expected a " + toString(c) + ", got a " +
                                toString(q.quadricClass()));
}

Eigen::Vector3d unitDirection(const Eigen::Vector3d& d, const char* field) {
  const double n = d.norm();
  if (!std::isfinite(n) || n < 1e-12)
    throw std::invalid_argument(std::string(field) + " must be a finite nonzero vector");
  return d / n;
}

void requirePositive(double v, const char* field) {
  if (!std::isfinite(v) || v <= 0)
    throw std::invalid_argument(std::string(field) + " must be finite and > 0, got " +
                                std::to_string(v));
}

Eigen::Vector3d vec3(const std::vector<double>& v, size_t offset) {
  return Eigen::Vector3d(v[offset], v[offset + 1], v[offset + 2]);
}

void append(std::vector<double>* out, const Eigen::Vector3d& v) {
  out->insert(out->end(), {v.x(), v.y(), v.z()});
}

const std::vector<double>& key(const std::map<std::string, std::vector<double>>& m,
                               const std::string& name, size_t length) {
  const auto it = m.find(name);
  if (it == m.end())
    throw std::invalid_argument("shape key '" + name + "' is missing");
  if (it->second.size() != length)
    throw std::invalid_argument("shape key '" + name + "' must have " + std::to_string(length) +
                                " values, got " + std::to_string(it->second.size()));
  return it->second;
}

}  // namespace

Eigen::Matrix3d rotationWithAxis(const Eigen::Vector3d& direction, int column) {
  const Eigen::Vector3d a = direction.normalized();
  const Eigen::Vector3d b = a.unitOrthogonal();
  const Eigen::Vector3d c = a.cross(b);
  Eigen::Matrix3d R;
  // Cyclic order keeps det = +1: (a, b, c) as columns (column, column+1, column+2) mod 3.
  R.col(column % 3) = a;
  R.col((column + 1) % 3) = b;
  R.col((column + 2) % 3) = c;
  return R;
}

PlaneShape planeShape(const QuadricModel& q) {
  requireClass(q, QuadricClass::kPlane, "planeShape");
  PlaneShape s;
  s.normal = q.pose().linear().col(0);
  s.offset = s.normal.dot(q.pose().translation());
  return s;
}

SphereShape sphereShape(const QuadricModel& q) {
  requireClass(q, QuadricClass::kSphere, "sphereShape");
  return {q.pose().translation(), 1.0 / q.scale().x()};
}

CylinderShape cylinderShape(const QuadricModel& q) {
  requireClass(q, QuadricClass::kCylinder, "cylinderShape");
  return {q.pose().translation(), q.pose().linear().col(2), 1.0 / q.scale().x()};
}

ConeShape coneShape(const QuadricModel& q) {
  requireClass(q, QuadricClass::kCone, "coneShape");
  return {q.pose().translation(), q.pose().linear().col(2), std::atan2(1.0, q.scale().x())};
}

QuadricModel quadricFromShape(const PlaneShape& s) {
  const Eigen::Vector3d n = unitDirection(s.normal, "plane normal");
  if (!std::isfinite(s.offset))
    throw std::invalid_argument("plane offset must be finite");
  return QuadricModel(QuadricClass::kPlane, makeIsometry(rotationWithAxis(n, 0), s.offset * n),
                 Eigen::Vector3d::Ones());
}

QuadricModel quadricFromShape(const SphereShape& s) {
  requirePositive(s.radius, "sphere radius");
  const double a = 1.0 / s.radius;
  return QuadricModel(QuadricClass::kSphere, makeIsometry(Eigen::Matrix3d::Identity(), s.center),
                 Eigen::Vector3d(a, a, a));
}

QuadricModel quadricFromShape(const CylinderShape& s) {
  requirePositive(s.radius, "cylinder radius");
  const Eigen::Vector3d d = unitDirection(s.axis, "cylinder axis");
  const double a = 1.0 / s.radius;
  return QuadricModel(QuadricClass::kCylinder, makeIsometry(rotationWithAxis(d, 2), s.point),
                 Eigen::Vector3d(a, a, 1));
}

QuadricModel quadricFromShape(const ConeShape& s) {
  if (!(s.half_angle > 0 && s.half_angle < M_PI / 2))
    throw std::invalid_argument("cone half_angle must be in (0, pi/2) rad, got " +
                                std::to_string(s.half_angle));
  const Eigen::Vector3d d = unitDirection(s.axis, "cone axis");
  const double a = 1.0 / std::tan(s.half_angle);
  return QuadricModel(QuadricClass::kCone, makeIsometry(rotationWithAxis(d, 2), s.apex),
                 Eigen::Vector3d(a, a, 1));
}

std::vector<double> shapeVector(const QuadricModel& q) {
  std::vector<double> out;
  switch (q.quadricClass()) {
    case QuadricClass::kPlane: {
      const PlaneShape s = planeShape(q);
      append(&out, s.normal);
      out.push_back(s.offset);
      break;
    }
    case QuadricClass::kSphere: {
      const SphereShape s = sphereShape(q);
      append(&out, s.center);
      out.push_back(s.radius);
      break;
    }
    case QuadricClass::kCylinder: {
      const CylinderShape s = cylinderShape(q);
      append(&out, s.point);
      append(&out, s.axis);
      out.push_back(s.radius);
      break;
    }
    case QuadricClass::kCone: {
      const ConeShape s = coneShape(q);
      append(&out, s.apex);
      append(&out, s.axis);
      out.push_back(s.half_angle);
      break;
    }
    case QuadricClass::kGeneral:
      break;
  }
  return out;
}

QuadricModel quadricFromShapeVector(QuadricClass c, const std::vector<double>& v) {
  const size_t expected = c == QuadricClass::kPlane || c == QuadricClass::kSphere ? 4 : 7;
  if (c == QuadricClass::kGeneral)
    throw std::invalid_argument(
        "quadricFromShapeVector: a general quadric has no shape vector (use pose and scale)");
  if (v.size() != expected)
    throw std::invalid_argument("quadricFromShapeVector: a " + toString(c) + " shape has " +
                                std::to_string(expected) + " values, got " +
                                std::to_string(v.size()));
  switch (c) {
    case QuadricClass::kPlane:
      return quadricFromShape(PlaneShape{vec3(v, 0), v[3]});
    case QuadricClass::kSphere:
      return quadricFromShape(SphereShape{vec3(v, 0), v[3]});
    case QuadricClass::kCylinder:
      return quadricFromShape(CylinderShape{vec3(v, 0), vec3(v, 3), v[6]});
    default:
      return quadricFromShape(ConeShape{vec3(v, 0), vec3(v, 3), v[6]});
  }
}

std::map<std::string, std::vector<double>> shapeMap(const QuadricModel& q) {
  const std::vector<double> v = shapeVector(q);
  switch (q.quadricClass()) {
    case QuadricClass::kPlane:
      return {{"normal", {v[0], v[1], v[2]}}, {"offset", {v[3]}}};
    case QuadricClass::kSphere:
      return {{"center", {v[0], v[1], v[2]}}, {"radius", {v[3]}}};
    case QuadricClass::kCylinder:
      return {{"point", {v[0], v[1], v[2]}}, {"axis", {v[3], v[4], v[5]}}, {"radius", {v[6]}}};
    case QuadricClass::kCone:
      return {{"apex", {v[0], v[1], v[2]}}, {"axis", {v[3], v[4], v[5]}}, {"half_angle", {v[6]}}};
    case QuadricClass::kGeneral:
      break;
  }
  return {};
}

QuadricModel quadricFromShapeMap(QuadricClass c, const std::map<std::string, std::vector<double>>& m) {
  std::vector<double> v;
  switch (c) {
    case QuadricClass::kPlane:
      v = key(m, "normal", 3);
      v.push_back(key(m, "offset", 1)[0]);
      break;
    case QuadricClass::kSphere:
      v = key(m, "center", 3);
      v.push_back(key(m, "radius", 1)[0]);
      break;
    case QuadricClass::kCylinder:
      v = key(m, "point", 3);
      for (double x : key(m, "axis", 3))
        v.push_back(x);
      v.push_back(key(m, "radius", 1)[0]);
      break;
    case QuadricClass::kCone:
      v = key(m, "apex", 3);
      for (double x : key(m, "axis", 3))
        v.push_back(x);
      v.push_back(key(m, "half_angle", 1)[0]);
      break;
    case QuadricClass::kGeneral:
      break;
  }
  return quadricFromShapeVector(c, v);
}

}  // namespace quadric_slam
