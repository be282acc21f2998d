// Matched image corners with a depth (odometry/feature_motion_guess.h) judged and fitted by what
// an RGB-D sensor measures well and badly: a corner's pixel is known to about a pixel at its
// pyramid level, its depth only to the disparity noise, which grows as z^2 (several centimetres
// at 3 m). A 3D distance gate wide enough for that depth noise lets motions several centimetres
// apart agree with the same far corners; reprojecting each corner into the other image keeps the
// pixel's precision across the view, and the depth is checked along the ray alone.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/types/camera_intrinsics.h"

namespace quadric_slam {

// One image's side of a set of matched corners (columns in match order).
struct MatchedCorners {
  Eigen::Matrix3Xd points;       // camera frame (m)
  Eigen::Matrix2Xd pixels;       // sub-pixel corner positions
  Eigen::VectorXd pixel_scales;  // the corner's pyramid-level scale (1 at full resolution)
  CameraIntrinsics intrinsics;   // of the image the pixels are in
};

// How far a matched pair may be from a motion and still agree with it.
struct CornerPairGates {
  // Reprojection error in each image (pixels at the corner's pyramid level). > 0
  double pixels = 3.0;
  // Depth difference along the ray: depth + depth_per_z2 z^2 (m; z the corner's depth), the
  // sensor's disparity noise grown to a gate. > 0 and >= 0
  double depth = 0.02;
  double depth_per_z2 = 0.01;
};

// The pairs (column indices) that agree with T_reference_current: each corner, moved into the
// other camera, reprojects within the pixel gate of its match and lies within the depth gate of
// its match's depth.
std::vector<int> cornerPairsAgreeing(const MatchedCorners& reference, const MatchedCorners& current,
                                     const Eigen::Isometry3d& T_reference_current,
                                     const CornerPairGates& gates);

// T_reference_current refined over the pairs `used` by robust least squares (Ceres, Huber loss at
// one standard deviation) on the reprojection errors in both images and the depth differences
// along both rays, each divided by its standard deviation (the pixel scale; a third of the depth
// gate). The start must be within the gates of most of the pairs.
Eigen::Isometry3d refineCornerPairPose(const MatchedCorners& reference,
                                       const MatchedCorners& current, const std::vector<int>& used,
                                       const Eigen::Isometry3d& T_reference_current,
                                       const CornerPairGates& gates);

// The information (inverse covariance) the pairs `used` give T_reference_current, for its left
// perturbation xi = (v, omega) in the reference frame, T = exp(xi^) T_hat (the ICP's convention,
// odometry/point_to_plane_icp.h): J^T W J of the residuals refineCornerPairPose minimises, J by
// central differences, W the Huber weights at T.
Matrix6d cornerPairInformation(const MatchedCorners& reference, const MatchedCorners& current,
                               const std::vector<int>& used,
                               const Eigen::Isometry3d& T_reference_current,
                               const CornerPairGates& gates);

}  // namespace quadric_slam
