#include "quadric_slam/frontend/primitive_shape.h"

#include <cmath>
#include <stdexcept>

namespace quadric_slam {

namespace {

// Completes a unit vector to a right-handed rotation whose column `axis` is the vector.
Eigen::Matrix3d frameWithAxis(const Eigen::Vector3d& unit, int axis) {
  const Eigen::Vector3d a = unit.normalized();
  const Eigen::Vector3d b = a.unitOrthogonal();
  const Eigen::Vector3d c = a.cross(b);
  Eigen::Matrix3d R;
  if (axis == 0) {
    R << a, b, c;
  } else {  // axis == 2: columns (b, c, a) are right-handed since b x c = a
    R << b, c, a;
  }
  return R;
}

}  // namespace

PrimitiveShape PrimitiveShape::plane(const Eigen::Vector3d& normal, double offset) {
  PrimitiveShape s;
  s.quadric_class = QuadricClass::kPlane;
  s.direction = normal.normalized();
  s.point = s.direction * offset;
  return s;
}

PrimitiveShape PrimitiveShape::sphere(const Eigen::Vector3d& centre, double radius) {
  PrimitiveShape s;
  s.quadric_class = QuadricClass::kSphere;
  s.point = centre;
  s.size = radius;
  return s;
}

PrimitiveShape PrimitiveShape::cylinder(const Eigen::Vector3d& point, const Eigen::Vector3d& axis,
                                        double radius) {
  PrimitiveShape s;
  s.quadric_class = QuadricClass::kCylinder;
  s.point = point;
  s.direction = axis.normalized();
  s.size = radius;
  return s;
}

PrimitiveShape PrimitiveShape::cone(const Eigen::Vector3d& apex, const Eigen::Vector3d& axis,
                                    double half_angle) {
  PrimitiveShape s;
  s.quadric_class = QuadricClass::kCone;
  s.point = apex;
  s.direction = axis.normalized();
  s.size = half_angle;
  return s;
}

std::vector<double> PrimitiveShape::shapeVector() const {
  const Eigen::Vector3d& p = point;
  const Eigen::Vector3d& d = direction;
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return {d.x(), d.y(), d.z(), planeOffset()};
    case QuadricClass::kSphere:
      return {p.x(), p.y(), p.z(), size};
    case QuadricClass::kCylinder:
    case QuadricClass::kCone:
      return {p.x(), p.y(), p.z(), d.x(), d.y(), d.z(), size};
    default:
      throw std::invalid_argument("PrimitiveShape: class general has no primitive shape");
  }
}

std::map<std::string, std::vector<double>> PrimitiveShape::schemaShape() const {
  const std::vector<double> p = {point.x(), point.y(), point.z()};
  const std::vector<double> d = {direction.x(), direction.y(), direction.z()};
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return {{"normal", d}, {"offset", {planeOffset()}}};
    case QuadricClass::kSphere:
      return {{"center", p}, {"radius", {size}}};
    case QuadricClass::kCylinder:
      return {{"point", p}, {"axis", d}, {"radius", {size}}};
    case QuadricClass::kCone:
      return {{"apex", p}, {"axis", d}, {"half_angle", {size}}};
    default:
      throw std::invalid_argument("PrimitiveShape: class general has no primitive shape");
  }
}

Eigen::Isometry3d PrimitiveShape::poseInFrame() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = point;
  if (quadric_class == QuadricClass::kPlane) {
    T.linear() = frameWithAxis(direction, 0);
  } else if (quadric_class == QuadricClass::kCylinder || quadric_class == QuadricClass::kCone) {
    T.linear() = frameWithAxis(direction, 2);
  }
  return T;
}

Eigen::Vector3d PrimitiveShape::scale() const {
  switch (quadric_class) {
    case QuadricClass::kSphere:
      return Eigen::Vector3d::Constant(1.0 / size);
    case QuadricClass::kCylinder:
      return Eigen::Vector3d(1.0 / size, 1.0 / size, 1.0);
    case QuadricClass::kCone: {
      const double a = 1.0 / std::tan(size);
      return Eigen::Vector3d(a, a, 1.0);
    }
    default:
      return Eigen::Vector3d::Ones();
  }
}

PrimitiveShape PrimitiveShape::fromPose(QuadricClass quadric_class,
                                        const Eigen::Isometry3d& T_frame_quadric,
                                        const Eigen::Vector3d& scale) {
  const Eigen::Vector3d t = T_frame_quadric.translation();
  const Eigen::Matrix3d R = T_frame_quadric.linear();
  switch (quadric_class) {
    case QuadricClass::kPlane: {
      PrimitiveShape s;
      s.quadric_class = QuadricClass::kPlane;
      s.direction = R.col(0).normalized();
      s.point = t;
      return s;
    }
    case QuadricClass::kSphere:
      return sphere(t, 1.0 / scale.x());
    case QuadricClass::kCylinder:
      return cylinder(t, R.col(2), 1.0 / scale.x());
    case QuadricClass::kCone:
      return cone(t, R.col(2), std::atan(1.0 / scale.x()));
    default:
      throw std::invalid_argument("PrimitiveShape: class general has no primitive shape");
  }
}

double PrimitiveShape::distance(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d v = p - point;
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return direction.dot(v);
    case QuadricClass::kSphere:
      return v.norm() - size;
    case QuadricClass::kCylinder:
      return (v - direction.dot(v) * direction).norm() - size;
    case QuadricClass::kCone: {
      const double z = direction.dot(v);
      const double rho = (v - z * direction).norm();
      return rho * std::cos(size) - z * std::sin(size);
    }
    default:
      return 0.0;
  }
}

Eigen::Vector3d PrimitiveShape::normalAt(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d v = p - point;
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return direction;
    case QuadricClass::kSphere:
      return v.normalized();
    case QuadricClass::kCylinder:
      return (v - direction.dot(v) * direction).normalized();
    case QuadricClass::kCone: {
      const double z = direction.dot(v);
      const Eigen::Vector3d radial = (v - z * direction).normalized();
      return (std::cos(size) * radial - std::sin(size) * direction).normalized();
    }
    default:
      return Eigen::Vector3d::UnitZ();
  }
}

PrimitiveShape PrimitiveShape::transformed(const Eigen::Isometry3d& T_b_a) const {
  PrimitiveShape s = *this;
  s.point = T_b_a * point;
  s.direction = T_b_a.linear() * direction;
  return s;
}

const std::vector<int>& minimalIndices(QuadricClass quadric_class) {
  // Table II, one row per class: indices into (rho1, rho2, rho3, phi1, phi2, phi3, s).
  static const std::vector<int> kPlane = {0, 4, 5};
  static const std::vector<int> kSphere = {0, 1, 2, 6};
  static const std::vector<int> kCylinder = {0, 1, 3, 4, 6};
  static const std::vector<int> kCone = {0, 1, 2, 3, 4, 6};
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return kPlane;
    case QuadricClass::kSphere:
      return kSphere;
    case QuadricClass::kCylinder:
      return kCylinder;
    case QuadricClass::kCone:
      return kCone;
    default:
      throw std::invalid_argument("minimalIndices: class general is not a primitive");
  }
}

PrimitiveShape perturb(const PrimitiveShape& shape, const Eigen::VectorXd& delta) {
  const std::vector<int>& indices = minimalIndices(shape.quadric_class);
  if (delta.size() != static_cast<int>(indices.size())) {
    throw std::invalid_argument("perturb: delta has the wrong dimension for the class");
  }
  Eigen::Matrix<double, 7, 1> full = Eigen::Matrix<double, 7, 1>::Zero();
  for (std::size_t i = 0; i < indices.size(); ++i)
    full[indices[i]] = delta[i];
  const Eigen::Vector3d rho = full.head<3>();
  const Eigen::Vector3d phi = full.segment<3>(3);
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const double angle = phi.norm();
  if (angle > 0)
    step.linear() = Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
  step.translation() = rho;
  // pi [+] dpi = (T exp(xi), S + D(s)) in the quadric frame (eqs. 10-17).
  const Eigen::Isometry3d T = shape.poseInFrame() * step;
  Eigen::Vector3d scale = shape.scale();
  scale.x() += full[6];  // alpha; fromPose reads the radial scale from x (y equals it)
  return PrimitiveShape::fromPose(shape.quadric_class, T, scale);
}

}  // namespace quadric_slam
