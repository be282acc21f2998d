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

// The model error of one view's ellipsoid as a covariance in its minimal tangent (general row of
// Table II: rho, phi, scale), to be added to the least-squares covariance: a depth camera sees one
// side of the surface with spatially correlated noise, so the fitted semi-axes stray by about
// `sigma` (m) from view to view, far beyond sigma^2 (J^T J)^-1 of independent points.
// Diagonal: translation sigma^2; rotation (sigma / smallest semi-axis)^2; scale (sigma s_i^2)^2
// (s = 1 / semi-axis, so ds = da / a^2). Throws std::invalid_argument for a quadric that is not an
// ellipsoid or sigma < 0.
Eigen::MatrixXd ellipsoidModelCovariance(const QuadricModel& quadric, double sigma);

}  // namespace quadric_slam
