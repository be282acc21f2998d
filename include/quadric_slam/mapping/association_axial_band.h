// Cylinder <-> cone association. A segmenter that sees only a short band of a cone (far away, or a
// shallow shade) often reports it as a cylinder, and a slender cylinder can come back as a cone of
// small half-angle; the two classes never meet in the observation cost (eqs. 20-22 compare quadrics
// of one class), so without this test one surface becomes a landmark of each class. Here the
// observed surface is compared with a landmark of the other axial class where it was seen: points
// of the observed quadric inside its box of supporting points (a grid over the band's height and
// the angles the box covers) are moved into the landmark's frame, and their RMS distance to the
// landmark's surface is the cone's local radius and axis tested over the observed band, which a
// tilted or short cylinder fit of a cone band still passes.
#pragma once

#include <Eigen/Geometry>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/mapping/extent_box.h"

namespace quadric_slam {

// True for a cylinder and a cone (in either order).
bool axialClassPair(const QuadricModel& a, const QuadricModel& b);

// Orthogonal distance (m) of point p (in the quadric's own frame) from a cylinder's or a cone's
// surface (the double cone: a symmetry of the quadric may name either nappe in its frame).
// Throws std::invalid_argument for the other classes.
double axialSurfaceDistance(const QuadricModel& axial, const Eigen::Vector3d& p_quadric);

// RMS distance (m) from the surface of `observed` (a cylinder or cone, in frame M), over its box of
// supporting points `observed_box` (in the observed quadric's frame), to the surface of `target`
// (the other axial class, in frame M). Infinity when the classes are not a cylinder/cone pair or
// the box is unknown or holds no point of the observed surface.
double axialBandDistance(const QuadricModel& observed, const ExtentBox& observed_box,
                         const QuadricModel& target);

}  // namespace quadric_slam
