// The Ceres problem of the offline batch refinement (mapping/batch_refiner.h) and what can be done
// to it: built from a recording and the mapper's online estimates, solved with the observations'
// variance factor re-estimated between solves, and landmarks merged into one another (their
// observations moved onto the survivor's block) between solves.
//   - every keyframe pose T_map_camera (PoseManifold), the first held fixed (the gauge), an
//     odometry factor between consecutive keyframes (RelativePoseCost);
//   - every landmark observed from a keyframe (QuadricManifold of its class), constant when it is
//     held fixed one by one (a loaded, trusted map), one QuadricObservationCost per observation
//     (eqs. 20-22) under the window's Huber loss, its covariance times the variance factor.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <map>
#include <memory>
#include <utility>
#include <vector>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/batch_recorder.h"
#include "quadric_slam/mapping/batch_refiner.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/solver_setup.h"

namespace quadric_slam {

class BatchProblem {
 public:
  // The problem at the online estimates. Observations of landmarks no longer in the mapper's map
  // are skipped (counted in stats). Fills the problem's sizes in `stats`.
  BatchProblem(const BatchRecorder& recorder, const QuadricMapper& mapper, BatchStatistics* stats);
  BatchProblem(const BatchProblem&) = delete;
  BatchProblem& operator=(const BatchProblem&) = delete;

  // Dog-leg solves (params.max_iterations each) with the variance factor (>= 1) estimated from
  // the whitened residuals before the first and after each solve, until it changes by no more
  // than params.noise_tolerance, at most max(1, params.noise_rounds) solves (the factor stays at
  // its current value when noise_rounds is 0). Adds the solves, iterations and costs to `stats`
  // (initial_cost only when stats->solves was 0); false when a solve's result is not usable.
  bool solve(const BatchRefiner::Params& params, BatchStatistics* stats);

  std::size_t keyframeCount() const { return poses_.size(); }
  Eigen::Isometry3d keyframePose(std::size_t i) const;

  // Landmarks with a block (observed from a keyframe), and which of them are constant.
  bool hasLandmark(int id) const { return landmarks_.count(id) > 0; }
  bool landmarkFixed(int id) const;
  // The block's estimate with the class and signature of `like`; throws std::invalid_argument
  // when it is no valid quadric (a scale pushed through zero).
  QuadricModel landmarkEstimate(int id, const QuadricModel& like) const;
  void setLandmarkEstimate(int id, const QuadricModel& estimate);
  // Marginal covariances of the free landmarks (mapping/solver_setup.h); empty when they cannot
  // be computed. With `cross`, the cross-covariances of `pairs` too, from the same factorisation.
  std::map<int, Eigen::MatrixXd> landmarkCovariances(
      const std::vector<std::pair<int, int>>& pairs = {},
      std::map<std::pair<int, int>, Eigen::MatrixXd>* cross = nullptr);
  // Cross-covariances of pairs of free landmarks (mapping/solver_setup.h); pairs with a constant
  // member, or that Ceres cannot give, are left out.
  std::map<std::pair<int, int>, Eigen::MatrixXd> landmarkCrossCovariances(
      const std::vector<std::pair<int, int>>& pairs);
  // Every observation of `merged` becomes one of `survivor` (same class), and merged's block goes.
  void mergeLandmark(int merged, int survivor);

  double varianceFactor() const { return factor_; }
  // Whitened observation residual norms (sigmas, before the robust loss) under the covariances
  // the blocks carry, sorted.
  std::vector<double> residualNorms() const;

 private:
  using PoseBlock = std::array<double, kPoseParameterSize>;
  using QuadricBlock = std::array<double, kQuadricParameterSize>;
  // One keyframe's observation of a landmark, and its residual block.
  struct Term {
    double* pose = nullptr;
    int landmark_id = 0;
    const QuadricMeasurement* measurement = nullptr;
    ceres::ResidualBlockId block = nullptr;
  };

  std::map<int, LandmarkBlock> freeLandmarkBlocks() const;
  void addTermBlock(Term* term);
  void setFactor(double factor);
  double estimateFactor() const;

  // The problem borrows these: declared first, destroyed after it.
  PoseManifold pose_manifold_;
  std::map<QuadricClass, std::unique_ptr<QuadricManifold>> quadric_manifolds_;
  std::unique_ptr<ceres::LossFunction> huber_;
  ceres::Problem problem_;
  // A landmark's parameter block and what the covariances and merges need of it.
  struct LandmarkEntry {
    QuadricBlock block{};
    int minimal_size = 0;
    bool fixed = false;
  };
  std::vector<PoseBlock> poses_;
  std::map<int, LandmarkEntry> landmarks_;  // node-based: block addresses stay put
  std::vector<Term> terms_;
  double factor_ = 1.0;
};

}  // namespace quadric_slam
