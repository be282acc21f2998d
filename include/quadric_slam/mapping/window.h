// Bounded-cost estimation: a sliding window over the last `size` keyframes. Each optimisation
// builds one Ceres problem from
//   - the window's keyframe poses T_map_camera (PoseManifold), odometry factors between
//     consecutive window keyframes (RelativePoseCost),
//   - the landmarks observed from window keyframes (QuadricManifold of their class) with one
//     QuadricObservationCost per observation (eqs. 20-22),
//   - the gauge: while the map's first keyframe is in the window it is held fixed (it defines the
//     map frame); afterwards the marginalisation prior below carries it,
//   - the marginalisation prior (schur_marginalization, the default): when a keyframe leaves the
//     window, its pose and the landmarks seen by no other window keyframe are eliminated from the
//     factors that touch them (its odometry factor, its observations, the previous prior) by a
//     Schur complement at the just-optimised estimate, and what they said about the variables
//     that stay becomes one dense linearised factor on those (mapping/linearized_prior.h: OKVIS /
//     VINS-Mono marginalisation, in the tangent spaces of the window's manifolds). Nothing of the
//     leaving keyframe's information is dropped (up to linearisation: the prior keeps its
//     Jacobian at the linearisation point). Its size is bounded by the window's variables.
//   - a landmark that was eliminated and is seen again (a loop) re-enters with a prior from its
//     marginal covariance in the map when it was eliminated (QuadricObservationCost of that
//     estimate from a constant identity pose, covariance landmark_prior_inflation * covariance).
//     Its history also lives on in the marginalisation prior through the poses it corrected, so
//     this prior counts part of that information twice; inflate to be conservative.
// The former approximation is kept as schur_marginalization = false ("folded priors"): the
// leaving keyframe's odometry is dropped, the oldest window pose gets a PosePriorCost at its
// current estimate, and each leaving observation is linearised with the leaving pose taken as known
// to that prior's accuracy and added to a per-landmark information (S = Sigma_z + J_c P J_c^T);
// the test of the window compares both against the full batch solution.
// The problem is solved with a bounded number of iterations, so the cost per keyframe depends on
// the window size and the landmarks in view, never on the sequence length. A landmark no longer
// observed by any window keyframe leaves the problem and keeps its last estimate and covariance in
// the map. Marginal covariances of the window's landmarks (ceres::Covariance, minimal tangent
// space) are computed after each optimisation when compute_covariance is set; a landmark whose
// covariance cannot be computed (rank-deficient window) keeps an empty one.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <deque>
#include <map>
#include <set>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/landmark_registry.h"
#include "quadric_slam/mapping/linearized_prior.h"
#include "quadric_slam/types/observation.h"

namespace quadric_slam {

struct WindowObservation {
  int landmark_id = 0;
  QuadricMeasurement measurement;  // validated: finite, k x k positive definite covariance
};

struct Keyframe {
  int frame_index = 0;                                              // the mapper's frame counter
  double stamp = 0.0;                                               // s
  Eigen::Isometry3d T_map_camera = Eigen::Isometry3d::Identity();   // estimate
  Eigen::Isometry3d T_odom_camera = Eigen::Isometry3d::Identity();  // odometry
  // Odometry from the previous keyframe to this one, T_prev_this, and its covariance in this
  // keyframe's body tangent [rho; phi] (unused for the map's first keyframe).
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();
  Matrix6d increment_covariance = Matrix6d::Identity();
  std::vector<WindowObservation> observations;
};

// Size of the last optimisation problem and how it went.
struct WindowStatistics {
  int keyframes = 0;
  int pose_blocks = 0;       // variable and fixed window poses
  int landmark_blocks = 0;   // landmarks in the window
  int parameter_blocks = 0;  // as Ceres counts them (the constant identity pose of priors included)
  int residual_blocks = 0;
  int residuals = 0;
  int observation_factors = 0, odometry_factors = 0, pose_priors = 0, landmark_priors = 0;
  int marginalization_priors = 0;  // 0 or 1: the dense prior of the keyframes that left
  int marginalized_keyframes = 0;  // keyframes eliminated after this optimisation
  int marginal_prior_rows = 0;     // residuals of the prior left for the next optimisation
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  bool solution_usable = false;
};

class SlidingWindow {
 public:
  struct Params {
    int size = 10;            // keyframes in the window, [2, 1000]
    int max_iterations = 10;  // Levenberg-Marquardt iterations per optimisation, [1, 1000]
    // Huber loss on the whitened observation residual (in sigmas), 0 = plain least squares; >= 0.
    double observation_huber = 3.0;
    // true: a leaving keyframe is marginalised (Schur complement into a dense linearised prior on
    // the variables that stay, see above); false: the folded priors (its odometry dropped, the
    // oldest pose held by the prior below, its observations folded into landmark priors).
    bool schur_marginalization = true;
    // Prior holding the oldest window pose once the first keyframe has left, in the folded mode
    // or when no marginalisation prior could be formed (1-sigma, body frame): m and rad, > 0.
    double oldest_pose_translation_sigma = 0.005;
    double oldest_pose_rotation_sigma = 0.002;
    // Landmark priors: factor (>= 1) on the folded covariance (the folding treats leaving poses
    // as known to the oldest-pose prior's accuracy) or, with schur_marginalization, on the
    // covariance of a landmark re-entering the window; inflate to be more conservative.
    double landmark_prior_inflation = 1.0;
    // Compute the landmarks' marginal covariances after each optimisation.
    bool compute_covariance = true;

    // Throws std::invalid_argument naming the bad field and its allowed range.
    void validate() const;
  };

  SlidingWindow() : SlidingWindow(Params{}) {}
  explicit SlidingWindow(const Params& params);

  // Appends a keyframe (its T_map_camera initialised by the caller; its observations must name
  // landmarks of `map`). When the window is over its size the oldest keyframe leaves: at once in
  // the folded mode, after the next optimize() (which marginalises it at its optimised estimate)
  // with schur_marginalization; landmarks that lose their last window observation leave the
  // problem.
  void addKeyframe(Keyframe keyframe, const LandmarkRegistry& map);
  // Adds an observation of a landmark to the window keyframe of frame `frame_index` (the earlier
  // frames of a just-promoted candidate). Returns false when that frame is not a window keyframe.
  bool addObservation(int frame_index, const WindowObservation& observation);

  // Optimises the window and writes the estimates back (keyframe poses here, landmarks into the
  // map), then marginalises the keyframes over the window's size (schur_marginalization). When
  // the solver fails or a landmark's estimate becomes invalid, the old estimates stay (the
  // keyframes over the size are then marginalised at those).
  WindowStatistics optimize(LandmarkRegistry* map);

  const std::deque<Keyframe>& keyframes() const { return keyframes_; }
  bool containsLandmark(int landmark_id) const {
    return observation_counts_.count(landmark_id) > 0;
  }
  const WindowStatistics& lastStatistics() const { return last_; }
  // The marginalisation prior the next optimisation will use (empty before a keyframe has left,
  // and in the folded mode).
  const LinearizedPrior& marginalizationPrior() const { return marginal_prior_; }

  // Fixed landmarks (a trusted, loaded map) are constant blocks of the optimisation: their
  // observations still correct the poses, but their estimates and covariances in the map are left
  // as they are and no prior is folded for them. setLandmarkFixed marks one landmark (state,
  // forgotten by clear()); setAllLandmarksFixed(true) holds every landmark (localisation only; a
  // mode, kept by clear()).
  void setLandmarkFixed(int landmark_id, bool fixed = true);
  void setAllLandmarksFixed(bool fixed) { all_landmarks_fixed_ = fixed; }
  bool landmarkFixed(int landmark_id) const {
    return all_landmarks_fixed_ || fixed_landmarks_.count(landmark_id) > 0;
  }
  // The landmarks marked one by one (setLandmarkFixed), without the all-fixed mode.
  const std::set<int>& individuallyFixedLandmarks() const { return fixed_landmarks_; }

  // Landmark merged_id was merged into survivor_id (mapping/landmark_merger.h): its observations
  // in the window keyframes become the survivor's (the same measurements, now factors on the
  // survivor), the marginalisation prior eliminates it (its information passes to the other
  // variables of the prior: the two landmarks' frames differ, so its columns cannot simply be
  // renamed), and its folded / re-entry prior is fused into the survivor's (surface_fusion.h: information
  // added, means combined; a prior of the merged landmark alone is re-expressed in the frame of
  // survivor_estimate, the survivor's estimate in the map). A fixed merged landmark makes the
  // survivor fixed.
  void mergeLandmark(int merged_id, int survivor_id, const QuadricModel& survivor_estimate);
  // The landmarks with at least one observation in the window.
  std::set<int> landmarkIds() const;

  void clear();

  const Params& params() const { return params_; }

 private:
  void countObservation(int landmark_id);
  void foldIntoPrior(const Keyframe& keyframe, const WindowObservation& observation,
                     const LandmarkRegistry& map);
  void dropFront();  // removes the oldest keyframe and its observation counts
  struct Problem;
  // Eliminates the oldest keyframe (and the landmarks only it observes) from `problem` at the
  // current estimates into marginal_prior_ (schur_marginalization).
  void marginalizeOldest(Problem* problem, const LandmarkRegistry& map);
  // After a solve: poses into the keyframes, free landmarks (and covariances) into the map.
  void writeBack(Problem* problem, const std::vector<double*>& poses, LandmarkRegistry* map);
  // After a failed solve: the blocks back to the estimates the solve started from.
  void resetBlocks(Problem* problem, const std::vector<double*>& poses,
                   const LandmarkRegistry& map);

  Params params_;
  std::deque<Keyframe> keyframes_;
  bool first_keyframe_in_window_ = false;
  bool any_keyframe_ = false;
  std::map<int, int> observation_counts_;  // landmark id -> observations in the window
  struct LandmarkPrior {
    QuadricModel quadric_map;     // mean: the estimate when the latest observation was folded in
    Eigen::MatrixXd information;  // k x k, minimal tangent
  };
  // Landmarks whose observations from keyframes that left the window were folded in (one entry
  // per landmark: grows with the map, not with the sequence).
  std::map<int, LandmarkPrior> priors_;
  LinearizedPrior marginal_prior_;
  std::set<int> fixed_landmarks_;
  bool all_landmarks_fixed_ = false;
  WindowStatistics last_;
};

}  // namespace quadric_slam
