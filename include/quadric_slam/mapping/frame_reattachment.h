// Re-attaching the mapped frames to refined keyframes (after the offline batch, which estimates the
// keyframes only; mapping/batch_refiner.h).
//
// A frame between two refined keyframes a and b is a node of the odometry chain
//   X_k = X_a Z_1 exp(xi_1^) ... Z_k exp(xi_k^),
// Z_i the odometry increment recorded on frame i and xi_i ~ N(0, Sigma_i) its error in that frame's
// body tangent (QuadricMapper's increment covariance). With X_a and X_b held at their refined poses
// the most probable chain is
//   min sum_i xi_i^T Sigma_i^-1 xi_i   subject to   X_a Z_1 exp(xi_1^) ... Z_n exp(xi_n^) = X_b,
// linearised: sum_i J_i xi_i = delta, J_i = Ad(P_i^-1) (P_i = Z_{i+1} ... Z_n carries frame i's
// error to frame b), delta = log(X_pred_b^-1 X_b); solution xi_i = Sigma_i J_i^T M^-1 delta,
// M = sum_j J_j Sigma_j J_j^T, relinearised a few times. The refined keyframes' disagreement with
// the odometry so lands on the steps the odometry was least sure of (a degenerate frame takes the
// slide along its weak direction) instead of being carried forward from the earlier keyframe.
// Frames after the last keyframe hang from it through their odometry; frames before the first
// keep their online estimates. A chain whose disagreement is not small (more than 0.5 rad or 1 m,
// e.g. across a relocalisation that the odometry did not follow) or whose increments carry no
// covariance falls back to hanging from its earlier keyframe.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "quadric_slam/mapping/batch_recorder.h"

namespace quadric_slam {

struct RefinedPose {
  double stamp = 0.0;  // s
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();
};

// keyframe_poses[i] is the refined pose of recorder.keyframes()[i]; one RefinedPose per recorded
// frame, in order. Throws std::invalid_argument when the sizes differ.
std::vector<RefinedPose> reattachFrames(const BatchRecorder& recorder,
                                        const std::vector<Eigen::Isometry3d>& keyframe_poses);

// The chain above for one run of increments: X_start, the increments Z_1..Z_n with their
// covariances (body tangent of the frame each ends at, [rho; phi]), and X_end the pose the chain
// must reach. Returns X_1..X_n (X_n = X_end up to the linearisation; exactly the odometry chain
// when it already reaches X_end). Throws std::invalid_argument on mismatched sizes.
std::vector<Eigen::Isometry3d> smoothOdometryChain(const Eigen::Isometry3d& X_start,
                                                   const std::vector<Eigen::Isometry3d>& increments,
                                                   const std::vector<Matrix6d>& covariances,
                                                   const Eigen::Isometry3d& X_end);

}  // namespace quadric_slam
