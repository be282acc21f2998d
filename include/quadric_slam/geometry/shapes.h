// Human-readable shapes per class, following msg/QuadricSurface.msg exactly, and their packing into
// the message's flat `shape` vector and the map schema's shape keys (io/map_yaml.h).
//   plane:    unit normal n = quadric x axis, offset d with n.p = d (quadric origin = d n when
//   built) sphere:   centre = quadric origin, radius = 1/alpha cylinder: point on the axis =
//   quadric origin, unit direction = quadric z, radius = 1/alpha cone:     apex = quadric origin,
//   unit axis direction = quadric z, half-angle = atan(1/alpha)
// (A circular cone's quadric is the double cone; the direction "into the opening" is the quadric
// z axis, i.e. the nappe the frame names.) Units: metres and radians.
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

struct PlaneShape {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  // unit
  double offset = 0.0;                                // m, n.p = offset
};
struct SphereShape {
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 1.0;  // m
};
struct CylinderShape {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // on the axis
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit
  double radius = 1.0;                              // m
};
struct ConeShape {
  Eigen::Vector3d apex = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();  // unit, into the opening
  double half_angle = M_PI / 4;                     // rad, in (0, pi/2)
};

// Shape of a quadric; throws std::invalid_argument when the quadric is of another class.
PlaneShape planeShape(const QuadricModel& quadric);
SphereShape sphereShape(const QuadricModel& quadric);
CylinderShape cylinderShape(const QuadricModel& quadric);
ConeShape coneShape(const QuadricModel& quadric);

// The QuadricModel of a shape; directions need not be unit (they are normalised) but must be nonzero;
// radius > 0; half_angle in (0, pi/2). Throws std::invalid_argument naming the bad field.
QuadricModel quadricFromShape(const PlaneShape& shape);
QuadricModel quadricFromShape(const SphereShape& shape);
QuadricModel quadricFromShape(const CylinderShape& shape);
QuadricModel quadricFromShape(const ConeShape& shape);

// QuadricSurface.msg `shape`: plane [nx ny nz d], sphere [cx cy cz r], cylinder [px py pz dx dy dz
// r], cone [ax ay az dx dy dz half_angle], general [].
std::vector<double> shapeVector(const QuadricModel& quadric);
// Throws std::invalid_argument for the wrong length or for kGeneral (its shape is empty).
QuadricModel quadricFromShapeVector(QuadricClass quadric_class, const std::vector<double>& shape);

// Map schema keys (MapFileQuadric::shape): plane {normal, offset}; sphere {center, radius};
// cylinder {point, axis, radius}; cone {apex, axis, half_angle}; general {} (scalars: length 1).
std::map<std::string, std::vector<double>> shapeMap(const QuadricModel& quadric);
// Throws std::invalid_argument naming a missing key or a wrong length.
QuadricModel quadricFromShapeMap(QuadricClass quadric_class,
                            const std::map<std::string, std::vector<double>>& shape);

// A proper rotation whose column `column` (0 = x, 2 = z) is the unit vector `direction`.
Eigen::Matrix3d rotationWithAxis(const Eigen::Vector3d& direction, int column);

}  // namespace quadric_slam
