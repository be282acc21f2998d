// Shapes through minimal sets of points with normals (the proposals of a RANSAC for planes,
// spheres, circular cylinders and cones), and the test of whether a point with its normal fits a
// shape. Normals are unit; their sign is free.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <optional>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

struct OrientedPoint {
  Eigen::Vector3d p, n;
};

// The plane through s[0..2]; none when they are collinear.
std::optional<PrimitiveShape> planeThrough(const OrientedPoint* s);
// The sphere whose centre lies on the normal lines of s[0] and s[1] (their closest approach);
// none when the normals are parallel.
std::optional<PrimitiveShape> sphereThrough(const OrientedPoint* s);
// The cylinder whose axis is perpendicular to the normals of s[0] and s[1] and meets both normal
// lines; none when the normals are (nearly) parallel.
std::optional<PrimitiveShape> cylinderThrough(const OrientedPoint* s);
// The cone tangent to the planes of s[0..2] (apex where they meet), its axis into the opening;
// none when the planes do not meet in a point or the half angle is not in (0, pi/2).
std::optional<PrimitiveShape> coneThrough(const OrientedPoint* s);

// Whether a point with its normal fits a shape (within epsilon, normals within the threshold's
// angle), with the shape's constants computed once and no square root beyond the radial one: the
// test runs for every free point and every proposal.
class ShapeInlierTest {
 public:
  ShapeInlierTest(const PrimitiveShape& shape, double epsilon, double cos_min)
      : class_(shape.quadric_class),
        point_(shape.point),
        direction_(shape.direction),
        size_(shape.size),
        cos_(shape.quadric_class == QuadricClass::kCone ? std::cos(shape.size) : 1.0),
        sin_(shape.quadric_class == QuadricClass::kCone ? std::sin(shape.size) : 0.0),
        epsilon_(epsilon),
        cos_min_(cos_min) {}

  bool operator()(const Eigen::Vector3d& x, const Eigen::Vector3d& n) const {
    const Eigen::Vector3d v = x - point_;
    switch (class_) {
      case QuadricClass::kPlane:
        return std::abs(direction_.dot(v)) <= epsilon_ && std::abs(direction_.dot(n)) >= cos_min_;
      case QuadricClass::kSphere: {
        const double length = v.norm();  // the surface normal is v / length
        return std::abs(length - size_) <= epsilon_ && std::abs(v.dot(n)) >= cos_min_ * length;
      }
      case QuadricClass::kCylinder: {
        const Eigen::Vector3d radial = v - direction_.dot(v) * direction_;
        const double rho = radial.norm();  // the surface normal is radial / rho
        return std::abs(rho - size_) <= epsilon_ && std::abs(radial.dot(n)) >= cos_min_ * rho;
      }
      case QuadricClass::kCone: {
        // Distance rho cos(a) - z sin(a); normal cos(a) radial / rho - sin(a) direction.
        const double z = direction_.dot(v);
        const Eigen::Vector3d radial = v - z * direction_;
        const double rho = radial.norm();
        return std::abs(rho * cos_ - z * sin_) <= epsilon_ &&
               std::abs(cos_ * radial.dot(n) - sin_ * rho * direction_.dot(n)) >= cos_min_ * rho;
      }
      default:
        return false;
    }
  }

 private:
  QuadricClass class_;
  Eigen::Vector3d point_, direction_;
  double size_, cos_, sin_, epsilon_, cos_min_;
};

}  // namespace quadric_slam
