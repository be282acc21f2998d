// Marginal covariances of landmarks in a solved Ceres problem by the Schur complement on the other
// variables: the structure of a SLAM window (each observation ties one landmark to one pose) makes
// the landmarks' block of the information matrix block-diagonal, so
//   H = [Hll Hlp; Hpl Hpp],  S = Hpp - Hpl Hll^-1 Hlp,
//   Cov(l) = Hll_l^-1 + Hll_l^-1 Hlp_l S^-1 Hpl_l Hll_l^-1
// needs one small inverse per landmark and one dense inverse of the size of the other variables.
// ceres::Covariance (sparse QR of the whole Jacobian) gives the same figures at about 2.5x the
// cost on a kitchen window. Landmarks tied to another landmark by one residual (a marginalisation
// prior) join the dense part. H = J^T J at the current parameters, the loss functions applied,
// constant blocks held fixed: what ceres::Covariance computes.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <map>

#include "quadric_slam/mapping/solver_setup.h"

namespace quadric_slam {

// Writes the marginal covariances of `landmarks` (minimal tangent spaces) into *out and returns
// true; returns false (and *out is left empty) when the dense part would exceed
// max_dense_size, a block's tangent size differs from its minimal_size, or H is not positive
// definite where it must be inverted (a rank-deficient problem): the caller then falls back to
// ceres::Covariance.
bool schurLandmarkCovariances(ceres::Problem* problem,
                              const std::map<int, LandmarkBlock>& landmarks, int max_dense_size,
                              std::map<int, Eigen::MatrixXd>* out);

}  // namespace quadric_slam
