#include "quadric_slam/frontend/primitive_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/quadric_classes.h"
#include "quadric_slam/geometry/shapes.h"
#include "quadric_slam/geometry/surface_distance.h"

namespace quadric_slam {

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

PrimitiveShape PrimitiveShape::general(const QuadricModel& quadric) {
  if (quadric.quadricClass() != QuadricClass::kGeneral)
    throw std::invalid_argument("PrimitiveShape::general: the quadric is a " +
                                toString(quadric.quadricClass()));
  PrimitiveShape s;
  s.quadric_class = QuadricClass::kGeneral;
  s.general_quadric = quadric;
  s.point = quadric.pose().translation();
  s.direction = quadric.pose().linear().col(0);
  s.size = 1.0 / quadric.scale()[0];
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
      return {};
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
    default: {
      const Eigen::Vector3d radii = general_quadric.scale().cwiseInverse();
      return {{"center", p}, {"radii", {radii.x(), radii.y(), radii.z()}}};
    }
  }
}

QuadricModel PrimitiveShape::quadric() const {
  switch (quadric_class) {
    case QuadricClass::kPlane:
      return quadricFromShape(PlaneShape{direction, planeOffset()});
    case QuadricClass::kSphere:
      return quadricFromShape(SphereShape{point, size});
    case QuadricClass::kCylinder:
      return quadricFromShape(CylinderShape{point, direction, size});
    case QuadricClass::kCone:
      return quadricFromShape(ConeShape{point, direction, size});
    default:
      return general_quadric;
  }
}

PrimitiveShape PrimitiveShape::fromQuadric(const QuadricModel& q) {
  switch (q.quadricClass()) {
    case QuadricClass::kPlane: {
      const PlaneShape s = planeShape(q);
      // Keep the quadric origin as the plane point (it lies on the plane).
      PrimitiveShape p = plane(s.normal, s.offset);
      p.point = q.pose().translation();
      return p;
    }
    case QuadricClass::kSphere: {
      const SphereShape s = sphereShape(q);
      return sphere(s.center, s.radius);
    }
    case QuadricClass::kCylinder: {
      const CylinderShape s = cylinderShape(q);
      return cylinder(s.point, s.axis, s.radius);
    }
    case QuadricClass::kCone: {
      const ConeShape s = coneShape(q);
      return cone(s.apex, s.axis, s.half_angle);
    }
    default:
      return general(q);
  }
}

namespace {

// cos and sin of a cone's half angle. The segmenter evaluates one cone at thousands of points in a
// row (refinement, labelling), and per point sincos was 3-4 % of its time in perf: the last angle's
// values are kept per thread (thread-local, so shapes may be evaluated from several threads).
struct ConeTrig {
  double cos_a;
  double sin_a;
};

ConeTrig coneTrig(double half_angle) {
  thread_local double last_angle = std::numeric_limits<double>::quiet_NaN();
  thread_local ConeTrig last{1.0, 0.0};
  if (half_angle != last_angle) {
    last = ConeTrig{std::cos(half_angle), std::sin(half_angle)};
    last_angle = half_angle;
  }
  return last;
}

}  // namespace

double PrimitiveShape::curvedDistance(const Eigen::Vector3d& p) const {
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
      const ConeTrig trig = coneTrig(size);
      return rho * trig.cos_a - z * trig.sin_a;
    }
    default: {
      // First-order distance f / |grad f| (Sampson); the floor keeps points at the centre, where
      // the gradient vanishes, finite and far.
      const AlgebraicValue a = algebraicValueAndSlope(general_quadric, p);
      return a.value / std::max(a.gradient_norm, 1e-9);
    }
  }
}

Eigen::Matrix<double, 7, 1> PrimitiveShape::distanceGradient(const Eigen::Vector3d& p) const {
  // Rows: d/d point (3), d/d direction (3), d/d size. v = p - point; for the axial classes
  // z = direction.v (height along the axis) and w = v - z direction (the radial part, |w| = rho).
  Eigen::Matrix<double, 7, 1> g = Eigen::Matrix<double, 7, 1>::Zero();
  const Eigen::Vector3d v = p - point;
  switch (quadric_class) {
    case QuadricClass::kPlane:  // d = n.v
      g.head<3>() = -direction;
      g.segment<3>(3) = v;
      return g;
    case QuadricClass::kSphere: {  // d = |v| - r
      const double norm = v.norm();
      if (norm > 0)
        g.head<3>() = -v / norm;
      g[6] = -1;
      return g;
    }
    case QuadricClass::kCylinder:
    case QuadricClass::kCone: {
      const double z = direction.dot(v);
      const Eigen::Vector3d w = v - z * direction;
      const double rho = w.norm();
      // d rho / d v = w^T / rho (w is orthogonal to the axis); d rho / d direction = -z w^T / rho.
      const Eigen::Vector3d radial = rho > 0 ? Eigen::Vector3d(w / rho) : Eigen::Vector3d::Zero();
      if (quadric_class == QuadricClass::kCylinder) {  // d = rho - r
        g.head<3>() = -radial;
        g.segment<3>(3) = -z * radial;
        g[6] = -1;
        return g;
      }
      // d = rho cos(a) - z sin(a), a the half angle; d z / d v = direction^T, d z / d direction =
      // v^T.
      const ConeTrig trig = coneTrig(size);
      const double c = trig.cos_a, s = trig.sin_a;
      g.head<3>() = -(c * radial - s * direction);
      g.segment<3>(3) = -c * z * radial - s * v;
      g[6] = -rho * s - z * c;
      return g;
    }
    default:
      throw std::invalid_argument("distanceGradient: not defined for a general quadric");
  }
}

Eigen::Vector3d PrimitiveShape::curvedNormalAt(const Eigen::Vector3d& p) const {
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
      const ConeTrig trig = coneTrig(size);
      return (trig.cos_a * radial - trig.sin_a * direction).normalized();
    }
    default: {
      const Eigen::Vector3d g = algebraicGradient(general_quadric, p);
      return g.norm() > 0 ? Eigen::Vector3d(g.normalized()) : Eigen::Vector3d::UnitZ();
    }
  }
}

PrimitiveShape PrimitiveShape::transformed(const Eigen::Isometry3d& T_b_a) const {
  PrimitiveShape s = *this;
  s.point = T_b_a * point;
  s.direction = T_b_a.linear() * direction;
  if (quadric_class == QuadricClass::kGeneral)
    s.general_quadric = general_quadric.transformed(T_b_a);
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
  if (delta.size() != minimalDimension(shape.quadric_class)) {
    throw std::invalid_argument("perturb: delta has the wrong dimension for the class");
  }
  // pi [+] dpi = (T exp(xi), S + D(s)) in the quadric frame (eqs. 9, 11, 16; Table II basis).
  const QuadricModel quadric = shape.quadric();
  // A step through alpha = 0 leaves the class (a negative radius, a cone half angle beyond pi/2):
  // the core's [+] would stop it at a thousandth of the scale (a radius a thousand times larger,
  // another surface), so the refiner's guarded step is told here instead.
  const Vector9d step =
      classDefinition(shape.quadric_class).basis * delta;  // plusMinimal's B delta
  const Eigen::Vector3d scale = quadric.scale() + step.tail<3>();
  if (!(scale.minCoeff() > 0) || !scale.allFinite())
    throw std::invalid_argument("perturb: the step leaves the class (scale " +
                                std::to_string(scale.minCoeff()) + " <= 0)");
  return PrimitiveShape::fromQuadric(quadric.plus(step));
}

}  // namespace quadric_slam
