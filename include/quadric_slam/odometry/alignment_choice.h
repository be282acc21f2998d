// Which of two ICP alignments of one frame the tracker keeps (OdometryTracker tries the
// constant-velocity prediction, the last pose and the surfaces' motion guess as starts).
#pragma once

#include "quadric_slam/odometry/photometric_refinement.h"
#include "quadric_slam/odometry/point_to_plane_icp.h"

namespace quadric_slam {

// a is the better alignment than b: not lost when b is; else more inlier correspondences (beyond
// 2%); at counts within 2% of each other, the smaller residual.
bool betterAlignment(const PointToPlaneIcp::Result& a, const PointToPlaneIcp::Result& b);

// How many more inliers (as a share of the prior's) a degenerate alignment from the surfaces'
// guess needs, when it leaves one more direction free than the prior's, to replace it.
constexpr double kGuessExtraCorrespondences = 0.05;

// The alignment from the surfaces' guess replaces the prior's when it is the better one and the
// depth backs the guess. An alignment keeps its start along the directions it leaves free, and
// there the guess is the surfaces' word alone: a box face matched to a parallel wall moved the
// camera 31-38 cm on generated fr1_room when every better guess alignment was taken. So a
// degenerate one replaces a degenerate (not lost) prior's only when it constrains more directions,
// or holds clearly more points while leaving at most one more direction free: from a prior 10 cm
// and 7 degrees off, a desk's top and side seen from above match only the top (3 of 6
// directions), from the guess top and side (5 of 6; the desk at 3 and 1.5 Hz). An ok alignment
// from the guess, or one against a lost prior, replaces it whenever it is the better one.
bool guessAlignmentReplaces(const PointToPlaneIcp::Result& from_guess,
                            const PointToPlaneIcp::Result& from_prior);

// aligned with its components along the columns of free (6 x k, orthonormal; left perturbation
// (v, omega) as pose_math::retractLeft) taken back to those of prior: the depth's answer along the
// directions it constrained, the prior's along the others. A degenerate alignment that started
// from the surfaces' guess keeps the guess along its free directions, where nothing measured it:
// on generated fr1_room one such step (a parallel surface matched to the wrong one) jumped 26.5 cm
// against 0.7 cm of true motion.
Eigen::Isometry3d priorAlongFreeDirections(const Eigen::Isometry3d& aligned,
                                           const Eigen::Isometry3d& prior,
                                           const Eigen::Matrix<double, 6, Eigen::Dynamic>& free);

// Of two photometric refinements of one frame from different starts, a matches the keyframe's
// intensities better than b: the lower intensity RMS, unless a kept fewer than
// kPhotometricMinPointShare of b's pixels in view (a start that pushes the frame off the keyframe's
// image keeps only a few pixels, whose RMS says little).
constexpr double kPhotometricMinPointShare = 0.75;
bool betterPhotometricMatch(const PhotometricRefinement::Result& a,
                            const PhotometricRefinement::Result& b);

}  // namespace quadric_slam
