// Starting shapes for the refinement of curved primitives, from points (and their normals): a
// cylinder from a thin cone, a cone from a cylinder fit, a cone or a cylinder from the normals
// alone; and a shape's own curvature over its support, which the segmenter compares with the
// measured normals' bending.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "quadric_slam/frontend/primitive_shape.h"

namespace quadric_slam {

// Cylinder through the points around the cone's axis (the degenerate thin cone).
PrimitiveShape cylinderFromCone(const PrimitiveShape& cone,
                                const std::vector<Eigen::Vector3d>& points);

// A cone through the points of a cylinder fit: the radius as a straight line of the axial
// coordinate, rho = r0 + k z; none (half angle 0) when k vanishes.
PrimitiveShape coneFromCylinder(const PrimitiveShape& cylinder,
                                const std::vector<Eigen::Vector3d>& points);

// The cone through the points of a cylinder fit whose axis is first tilted by `tilt` (rad) towards
// (sign +1) or away from (sign -1) the points, about the axis normal to both (coneFromCylinder on
// the tilted axis). A cylinder fitted to the visible side of a cone lies along the generator on
// that side, its axis tilted by about the half angle from the cone's: along the cylinder's own
// axis the radius does not change and the regression gives a thin cone that the refinement does
// not leave; along the tilted axis the radius grows and the cone's opening is found.
PrimitiveShape coneFromTiltedCylinder(const PrimitiveShape& cylinder,
                                      const std::vector<Eigen::Vector3d>& points, double tilt,
                                      double sign);

// A cone from points and their normals: every tangent plane passes through the apex
// (n_i . (apex - p_i) = 0, linear least squares), and the normals lie on a small circle around
// the axis (the least-variance direction of the centred normals). Catches the side view of a cone,
// whose visible strip a tilted cylinder also fits. Half angle 0 when degenerate.
PrimitiveShape coneFromNormals(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector3d>& normals);

// A cylinder of the given curvature (1/radius) from points and their normals: the normals are
// perpendicular to the axis (the least-variance direction of the normals, uncentred), and the axis
// runs through p -+ r n (the sign that gathers these feet best: normals towards the camera point
// out of a cylinder's outside and into its inside). Radius 0 when degenerate.
PrimitiveShape cylinderFromNormals(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& normals, double curvature);

// The curvature (1/m) with which the normals turn across the points as on a cylinder: about the
// least-variance direction of the normals (the axis), the normals' deviations from their mean
// regressed on the points' deviations perpendicular to it (n = +-(p - c) / r: outside or inside
// alike, the size of the slope). 0 when degenerate (fewer than 10 points, no spread).
double cylinderCurvatureFromNormals(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<Eigen::Vector3d>& normals);

// The largest principal curvature of a curved shape over its support (1/m): 1/r for a sphere or
// cylinder, cos(half angle) / (distance to the axis) for a cone (mean over the points).
double shapeCurvature(const PrimitiveShape& shape, const std::vector<Eigen::Vector3d>& points);

}  // namespace quadric_slam
