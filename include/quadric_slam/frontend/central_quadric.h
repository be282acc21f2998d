// The 10 coefficients of a general quadric fit (general_quadric_fit.h) as the paper's quadric
// pi = (T_frame_quadric, S, sigma) (Section III, eqs. 4-5): the symmetric 4x4 Q in the frame of the
// fitted points, decomposed by the geometry core (QuadricModel::fromMatrix: eigen-decomposition of
// the quadratic part, the centre from the linear part, the signature by Sylvester's law of
// inertia), for central quadrics only (ellipsoids, hyperboloids of one and two sheets), in a
// canonical axis order.
#pragma once

#include <Eigen/Core>

#include "quadric_slam/frontend/general_quadric_fit.h"
#include "quadric_slam/geometry/quadric.h"

namespace quadric_slam {

// Q (symmetric, defined up to scale) with p~^T Q p~ = f((p - centre) / spread) for points p in the
// frame of the fitted points: Q = N^T Q_n N with N = [I / spread, -centre / spread; 0 1].
Eigen::Matrix4d quadricMatrix(const GeneralQuadricFit& fit);

// The same quadric with its axes re-ordered (geometry/symmetry.h relabellings: the scales follow
// their axes) so that within each group of equal signature entries the scale entries ascend: an
// ellipsoid's semi-axes come longest first. Other classes are returned unchanged.
QuadricModel withCanonicalAxisOrder(const QuadricModel& quadric);

// The central quadric of the fit, class general, canonical axis order. Throws
// std::invalid_argument when the fit is not ok or its quadric is degenerate, has no real points,
// or is not central (paraboloids, cylinders and cones: a zero signature entry).
QuadricModel centralQuadricFromFit(const GeneralQuadricFit& fit);

}  // namespace quadric_slam
