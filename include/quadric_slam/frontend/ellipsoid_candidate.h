// Ellipsoids for the segmenter's general class: the central quadric of a general quadric fit
// (central_quadric.h) when it is an ellipsoid (signature (+1, +1, +1, -1)) of plausible size.
// Hyperboloids are not reported: a depth sensor sees one side of a surface, and a hyperboloid
// fitted to such a patch is as often a saddle of clutter (a bent cable, a fold of cloth) as a
// hyperboloid; the mapper handles their class should a later segmenter report them.
#pragma once

#include <optional>

#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/frontend/primitive_shape.h"
#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// Semi-axes of an ellipsoid (1 / scale, m); zeros for another signature.
Eigen::Vector3d semiAxes(const QuadricModel& quadric);

// True for a general quadric with the ellipsoid's signature whose semi-axes all lie in
// [min_semi_axis, max_semi_axis] (m).
bool plausibleEllipsoid(const QuadricModel& quadric, double min_semi_axis, double max_semi_axis);

// The fit's ellipsoid (class general, canonical axis order: longest semi-axis first) when
// plausible; none for a failed fit, a degenerate, non-central or non-ellipsoid quadric, or
// implausible semi-axes.
std::optional<PrimitiveShape> ellipsoidCandidate(const GeneralQuadricFit& fit,
                                                 double min_semi_axis, double max_semi_axis);

}  // namespace quadric_slam
