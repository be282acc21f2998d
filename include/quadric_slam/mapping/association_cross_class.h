// Association across classes. A segmenter that sees only part of a surface may fit it with another
// class than the rest of the time: a short or far band of a cone as a cylinder, a slender cylinder
// as a cone of small half-angle, a patch of a cone, a cylinder or an ellipsoid as a sphere. The
// observation cost (eqs. 20-22) compares quadrics of one class, so without this test one surface
// becomes a landmark of each class. Here the observed surface is compared with a landmark of
// another class where it was seen: points of the observed quadric inside its box of supporting
// points (a grid over the box) are moved into the landmark's frame, and their RMS distance to the
// landmark's surface decides. For a cylinder against a cone this is the cone's local radius and
// axis tested over the observed band, which a tilted or short cylinder fit of a band still passes.
// Pairs compared (observed -> landmark): cylinder <-> cone; sphere -> cylinder, cone, general;
// ellipsoid (general, signature +++-) -> sphere, cylinder, cone, general (a general fit of part of
// a surface is poorly determined: two fits of one patch can fail the gate of their parameters yet
// lie on each other). The same holds within a class: a partial view of a cone (its upper band, a
// few thousand pixels) or of a cylinder fits a shape whose parameters fail the association gate of
// the landmark it lies on, so cylinders, cones and spheres are also compared with landmarks of
// their own class here (only measurements the parameter gate refused reach this test).
#pragma once

#include <Eigen/Geometry>

#include "quadric_slam/geometry/quadric.h"
#include "quadric_slam/mapping/extent_box.h"

namespace quadric_slam {

// True when a measurement of `observed`'s class may be counted on a landmark of `target`'s class
// through the surface test (the pairs above).
bool surfaceTestApplies(const QuadricModel& observed, const QuadricModel& target);

// RMS distance (m) from the surface of `observed` (in frame M), over its box of supporting points
// `observed_box` (in the observed quadric's frame), to the surface of `target` (in frame M).
// Infinity when the pair is not one of the above, or the box is unknown or holds no point of the
// observed surface.
double crossClassDistance(const QuadricModel& observed, const ExtentBox& observed_box,
                          const QuadricModel& target);

}  // namespace quadric_slam
