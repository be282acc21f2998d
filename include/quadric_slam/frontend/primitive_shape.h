// A human-readable primitive (plane, sphere, cylinder, cone) in some frame, its geometric distance,
// and its quadric in the geometry core (geometry/shapes.h quadricFromShape: the pose, scale and
// Table II minimal perturbation all come from there). A general quadric (class general, e.g. an
// ellipsoid) is carried as its core quadric (pi = (T, S, sigma), Section III) with a first-order
// geometric distance.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/geometry/quadric_class.h"

namespace quadric_slam {

struct PrimitiveShape {
  QuadricClass quadric_class = QuadricClass::kPlane;
  // plane: a point on the plane; sphere: centre; cylinder: a point on the axis; cone: apex (m).
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  // plane: unit normal; cylinder, cone: unit axis (cone: from the apex into the opening); sphere:
  // unused.
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  // sphere, cylinder: radius (m); cone: half angle (rad); plane: unused.
  double size = 0.0;
  // general only: the quadric itself (point = its centre, direction = its first axis, size =
  // 1 / its first scale entry, the first semi-axis of an ellipsoid, for display).
  QuadricModel general_quadric;

  static PrimitiveShape plane(const Eigen::Vector3d& normal, double offset);
  static PrimitiveShape sphere(const Eigen::Vector3d& centre, double radius);
  static PrimitiveShape cylinder(const Eigen::Vector3d& point, const Eigen::Vector3d& axis,
                                 double radius);
  static PrimitiveShape cone(const Eigen::Vector3d& apex, const Eigen::Vector3d& axis,
                             double half_angle);
  // Throws std::invalid_argument when the quadric is not of class general.
  static PrimitiveShape general(const QuadricModel& quadric);

  // Plane offset n.p (points p with n.p = offset).
  double planeOffset() const { return direction.dot(point); }

  // The `shape` vector of msg/QuadricSurface.msg: plane [n, offset], sphere [c, r], cylinder
  // [p, d, r], cone [apex, d, half_angle], general [] (pose and scale say it all).
  std::vector<double> shapeVector() const;
  // The `shape` block of the map schema (io/map_yaml.h keys): plane normal, offset; sphere
  // center, radius; cylinder point, axis, radius; cone apex, axis, half_angle; general center,
  // radii (1 / scale: an ellipsoid's semi-axes).
  std::map<std::string, std::vector<double>> schemaShape() const;

  // The core quadric of this shape (geometry/shapes.h quadricFromShape: plane normal = quadric x
  // with origin offset * normal; sphere origin = centre; cylinder origin = the axis point, axis =
  // quadric z; cone origin = apex, axis = quadric z; general: general_quadric). Throws
  // std::invalid_argument for an invalid size.
  QuadricModel quadric() const;
  // Inverse of quadric() (planeShape, sphereShape, ... of geometry/shapes.h).
  static PrimitiveShape fromQuadric(const QuadricModel& quadric);

  // Signed geometric distance (m) of a point (same frame) to the surface: plane n.p - offset,
  // sphere |p - c| - r, cylinder (distance to axis) - r, cone rho cos(a) - z sin(a) in the cone
  // frame (exact near the nappe); general f / |grad f| (geometry/surface_distance.h: first order,
  // signed like f, finite: |grad f| is floored).
  // Planes (most calls: per pixel in the segmenter's upsampling and boundary passes) inline.
  double distance(const Eigen::Vector3d& p) const {
    return quadric_class == QuadricClass::kPlane ? direction.dot(p - point) : curvedDistance(p);
  }
  // Unit surface normal at the foot of p (sign not meaningful).
  Eigen::Vector3d normalAt(const Eigen::Vector3d& p) const {
    return quadric_class == QuadricClass::kPlane ? direction : curvedNormalAt(p);
  }
  // Gradient of distance(p) with respect to the shape's own parameters (point, direction, size),
  // direction taken as a free 3-vector: the per-point factor of the refiner's analytic Jacobian
  // (shape_refiner.h distanceJacobian). Plane, sphere, cylinder and cone; throws
  // std::invalid_argument for a general quadric.
  Eigen::Matrix<double, 7, 1> distanceGradient(const Eigen::Vector3d& p) const;
  // distance() and normalAt() of the other classes.
  double curvedDistance(const Eigen::Vector3d& p) const;
  Eigen::Vector3d curvedNormalAt(const Eigen::Vector3d& p) const;

  // The same surface expressed in another frame: T_b_a maps points of this shape's frame a to b.
  PrimitiveShape transformed(const Eigen::Isometry3d& T_b_a) const;
};

// The minimal parameters of a class (Table II, geometry/quadric_classes.h basis) as indices into
// the 7-vector (rho1, rho2, rho3, phi1, phi2, phi3, s) of a right (body-frame) perturbation of
// shape.quadric(): plane (rho1, phi2, phi3); sphere (rho1..3, s); cylinder (rho1, rho2, phi1, phi2,
// s); cone (rho1..3, phi1, phi2, s). The scale s perturbs alpha (sphere: 1/r on all three;
// cylinder: 1/r on x and y; cone: 1/tan(half_angle) on x and y).
const std::vector<int>& minimalIndices(QuadricClass quadric_class);

// pi [+] delta (eqs. 9-17) through the core: fromQuadric(shape.quadric().plusMinimal(delta)),
// delta with minimalDimension(class) entries ordered as minimalIndices() (general: the nine
// [rho; phi; alpha, beta, gamma] of Table II's general row). Throws
// std::invalid_argument when the step leaves the class (a scale alpha driven to <= 0).
PrimitiveShape perturb(const PrimitiveShape& shape, const Eigen::VectorXd& delta);

}  // namespace quadric_slam
