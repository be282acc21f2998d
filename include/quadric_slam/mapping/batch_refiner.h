// Offline batch refinement (the paper's batch solution of the factor graph, Fig. 3): after a run,
// one Ceres problem over ALL recorded keyframes and ALL landmarks (mapping/batch_recorder.h), with
// the factors and manifolds of the sliding window (mapping/window.h):
//   - every keyframe pose T_map_camera (PoseManifold), an odometry factor between consecutive
//     keyframes (RelativePoseCost, the recorded increment and its covariance),
//   - every landmark observed from a keyframe (QuadricManifold of its class) with one
//     QuadricObservationCost per observation (eqs. 20-22) under the window's Huber loss
//     (observation_huber), landmarks held fixed one by one (a loaded, trusted map) constant
//     (the localisation-only mode, also used while recovering from a loss of tracking, is not),
//   - the gauge: the first keyframe held fixed (it defines the map frame).
// The observations' covariances are first multiplied by a variance factor estimated from their own
// whitened residuals (mapping/observation_noise_scale.h), at the online estimates and again at each
// solution until it settles (at most noise_rounds solves): the segments' fit covariances describe
// pixel noise, not the scatter of a surface's observations between views.
// Under those honest covariances refined surfaces may turn out to be the same surface, with
// parameters that agree within their covariances and extents that touch (mapping/landmark_merger.h,
// the online map's merger and its tests): such landmarks are merged, the merged one's observations
// moved onto the survivor, and the problem solved again, for at most merge_rounds passes. The
// merges are reported (BatchSolution::merges) so that what is stored per landmark (reconstruction
// points) can follow.
// The problem itself is mapping/batch_problem.h.
// No marginalisation prior and no landmark re-entry prior: every factor they summarised is in the
// problem itself. Solved with the dog-leg trust region (ceres::DOGLEG, as the paper) for at most
// max_iterations iterations, starting from the online estimates.
// Then the mapped frames are re-attached to the refined keyframes through their odometry, the
// keyframes' disagreement with it spread over the steps between them by the steps' covariances
// (mapping/frame_reattachment.h).
// When the solve is not usable the online estimates are returned (solution_usable = false); a
// landmark whose refined estimate is invalid (a scale pushed through zero) keeps its online one.
// Cost: one sparse Schur solve over the whole run per iteration; memory and time grow with the
// run's keyframes and observations: offline only.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "quadric_slam/mapping/batch_recorder.h"
#include "quadric_slam/mapping/frame_reattachment.h"
#include "quadric_slam/mapping/landmark.h"
#include "quadric_slam/mapping/landmark_merger.h"
#include "quadric_slam/mapping/quadric_mapper.h"

namespace quadric_slam {

struct BatchStatistics {
  int keyframes = 0;
  int frames = 0;
  int landmarks = 0;        // landmark blocks (observed from a keyframe)
  int fixed_landmarks = 0;  // of which constant
  int observation_factors = 0, odometry_factors = 0;
  int skipped_observations =
      0;                      // of landmarks no longer in the map (none when merges are recorded)
  int invalid_landmarks = 0;  // refined estimate invalid: the online one kept
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  bool solution_usable = false;
  bool covariance_computed = false;  // false: the landmarks keep their online covariances
  std::string report;                // Ceres' one-line report
  // Whitened observation residual norms at the solution (sigmas, before the robust loss): how
  // well the measurement covariances describe the data (about sqrt(k) when they do).
  double observation_residual_median = 0.0, observation_residual_p95 = 0.0;
  // Variance factor the observation covariances were multiplied by (>= 1; 1 when the estimation
  // is off), and the solves it took.
  double observation_variance_factor = 1.0;
  int solves = 0;
  int merged_landmarks = 0;      // merged into another landmark (BatchSolution::merges)
  int unobserved_landmarks = 0;  // observed from no keyframe: left out of the refined map
  double solve_seconds = 0.0, covariance_seconds = 0.0;  // wall time
};

struct BatchSolution {
  BatchStatistics statistics;
  std::vector<Eigen::Isometry3d> keyframe_poses;  // per recorded keyframe, refined
  std::vector<RefinedPose> trajectory;            // per recorded frame, re-attached
  // The whole map (id order), refined estimates; merged landmarks removed, and (when the solution
  // is usable) those that no keyframe observes, which the batch could neither refine nor check.
  std::vector<QuadricLandmark> landmarks;
  std::vector<LandmarkMerge> merges;  // the batch's merges, in their order
  // Pairs of refined landmarks still the same surface after the merge passes (tested with their
  // cross-covariances): none when the passes converged.
  std::vector<DuplicatePair> duplicates;
};

class BatchRefiner {
 public:
  struct Params {
    // Dog-leg iterations, int in [1, 10000].
    int max_iterations = 100;
    // A larger recording is not solved (refine() returns the online estimates, not usable) and
    // QuadricSlam stops recording past it: the cost of an iteration grows up to cubically with the
    // keyframes (surfaces seen from every keyframe, a floor, make the reduced camera system
    // dense: 227 kitchen keyframes take 0.2 s an iteration), and the recording's memory with them.
    // int in [1, 1000000].
    int max_keyframes = 500;
    // Marginal covariances of the refined landmarks (ceres::Covariance over the whole problem);
    // false, or when they cannot be computed: the online covariances stay.
    bool compute_covariance = true;
    // Solves with a re-estimated observation variance factor: estimated at the online estimates,
    // then again at each solution, the problem solved again while it changed by more than
    // noise_tolerance (relative). 0 = off (the covariances as measured). int in [0, 10]; double
    // in (0, 10].
    int noise_rounds = 3;
    double noise_tolerance = 0.1;
    // Passes of merging duplicate landmarks after a solve (each landmark in at most one merge a
    // pass), each followed by a solve; 0 = off. int in [0, 10].
    int merge_rounds = 3;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  BatchRefiner() : BatchRefiner(Params{}) {}
  explicit BatchRefiner(const Params& params);

  // The refined trajectory and map of a run recorded by `recorder` from `mapper` (its map gives
  // the landmarks' online estimates, classes and which are fixed; its window the Huber loss).
  BatchSolution refine(const BatchRecorder& recorder, const QuadricMapper& mapper) const;

  const Params& params() const { return params_; }

 private:
  Params params_;
};

}  // namespace quadric_slam
