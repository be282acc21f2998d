#include "quadric_slam/mapping/batch_problem.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/observation_noise_scale.h"
#include "quadric_slam/mapping/solver_setup.h"

namespace quadric_slam {

namespace {

ceres::Problem::Options borrowingOptions() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

// The whitened residual of a block (before the robust loss) under the covariance it carries;
// false when it cannot be evaluated.
bool whitenedResidual(const ceres::Problem& problem, ceres::ResidualBlockId block,
                      Eigen::VectorXd* r) {
  r->resize(problem.GetCostFunctionForResidualBlock(block)->num_residuals());
  double cost = 0.0;
  return problem.EvaluateResidualBlock(block, false, &cost, r->data(), nullptr) && r->allFinite();
}

}  // namespace

BatchProblem::BatchProblem(const BatchRecorder& recorder, const QuadricMapper& mapper,
                           BatchStatistics* stats)
    : problem_(borrowingOptions()) {
  const LandmarkRegistry& map = mapper.map();
  const SlidingWindow& window = mapper.window();
  const std::vector<RecordedKeyframe>& keyframes = recorder.keyframes();
  if (window.params().observation_huber > 0.0)
    huber_ = std::make_unique<ceres::HuberLoss>(window.params().observation_huber);

  // Poses, the gauge and the odometry chain.
  poses_.resize(keyframes.size());
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    poseToParameters(keyframes[i].T_map_camera, poses_[i].data());
    problem_.AddParameterBlock(poses_[i].data(), kPoseParameterSize, &pose_manifold_);
  }
  if (!poses_.empty())
    problem_.SetParameterBlockConstant(poses_[0].data());
  for (std::size_t i = 1; i < keyframes.size(); ++i) {
    problem_.AddResidualBlock(
        RelativePoseCost::Create(keyframes[i].T_previous_this, keyframes[i].increment_covariance),
        nullptr, poses_[i - 1].data(), poses_[i].data());
    ++stats->odometry_factors;
  }

  // Landmarks and every keyframe observation of them. Landmarks held fixed one by one (a trusted,
  // loaded map) stay constant; the window's localisation-only mode (also set while recovering
  // from a loss of tracking) is a mode of the online estimation, not a property of the
  // landmarks: the batch refines them.
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    for (const WindowObservation& observation : keyframes[i].observations) {
      const int id = observation.landmark_id;
      if (map.landmarks().count(id) == 0) {
        ++stats->skipped_observations;
        continue;
      }
      auto it = landmarks_.find(id);
      if (it == landmarks_.end()) {
        const QuadricModel& online = map.landmark(id).quadric_map;
        it = landmarks_.emplace(id, LandmarkEntry{}).first;
        LandmarkEntry& entry = it->second;
        quadricToParameters(online, entry.block.data());
        auto& manifold = quadric_manifolds_[online.quadricClass()];
        if (!manifold)
          manifold = std::make_unique<QuadricManifold>(online.quadricClass());
        problem_.AddParameterBlock(entry.block.data(), kQuadricParameterSize, manifold.get());
        entry.minimal_size = minimalDimension(online.quadricClass());
        entry.fixed = window.individuallyFixedLandmarks().count(id) > 0;
        if (entry.fixed) {
          problem_.SetParameterBlockConstant(entry.block.data());
          ++stats->fixed_landmarks;
        }
      }
      terms_.push_back({poses_[i].data(), id, &observation.measurement, nullptr});
      addTermBlock(&terms_.back());
      ++stats->observation_factors;
    }
  }
  stats->landmarks = static_cast<int>(landmarks_.size());
}

void BatchProblem::addTermBlock(Term* term) {
  if (term->block != nullptr)
    problem_.RemoveResidualBlock(term->block);
  term->block = problem_.AddResidualBlock(
      QuadricObservationCost::Create(term->measurement->quadric_camera,
                                     term->measurement->covariance * factor_),
      huber_.get(), term->pose, landmarks_.at(term->landmark_id).block.data());
}

void BatchProblem::setFactor(double factor) {
  factor_ = factor;
  for (Term& term : terms_)
    addTermBlock(&term);
}

double BatchProblem::estimateFactor() const {
  // Residuals under the measured covariances are those under the blocks' scaled back.
  std::vector<WhitenedResidual> residuals;
  residuals.reserve(terms_.size());
  Eigen::VectorXd r;
  for (const Term& term : terms_)
    if (whitenedResidual(problem_, term.block, &r))
      residuals.push_back({static_cast<int>(r.size()), r.squaredNorm() * factor_});
  return observationVarianceFactor(residuals);
}

bool BatchProblem::solve(const BatchRefiner::Params& params, BatchStatistics* stats) {
  // The paper's batch solver: dog-leg.
  ceres::Solver::Options options = landmarkSolverOptions(params.max_iterations);
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.dogleg_type = ceres::TRADITIONAL_DOGLEG;
  const int solves = std::max(1, params.noise_rounds);
  bool usable = false;
  for (int round = 0; round < solves; ++round) {
    if (params.noise_rounds > 0) {
      const double estimated = estimateFactor();
      if (round > 0 && std::abs(estimated / factor_ - 1.0) <= params.noise_tolerance)
        break;
      setFactor(estimated);
    }
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem_, &summary);
    if (stats->solves == 0)
      stats->initial_cost = summary.initial_cost;
    ++stats->solves;
    stats->iterations += static_cast<int>(summary.iterations.size());
    stats->final_cost = summary.final_cost;
    stats->report = summary.BriefReport();
    usable = summary.IsSolutionUsable();
    if (!usable)
      break;
  }
  stats->observation_variance_factor = factor_;
  return usable;
}

Eigen::Isometry3d BatchProblem::keyframePose(std::size_t i) const {
  return poseFromParameters(poses_.at(i).data());
}

bool BatchProblem::landmarkFixed(int id) const {
  const auto it = landmarks_.find(id);
  return it != landmarks_.end() && it->second.fixed;
}

QuadricModel BatchProblem::landmarkEstimate(int id, const QuadricModel& like) const {
  return quadricFromParameters(landmarks_.at(id).block.data(), like.quadricClass(),
                               like.signature());
}

void BatchProblem::setLandmarkEstimate(int id, const QuadricModel& estimate) {
  quadricToParameters(estimate, landmarks_.at(id).block.data());
}

std::map<int, LandmarkBlock> BatchProblem::freeLandmarkBlocks() const {
  std::map<int, LandmarkBlock> free_blocks;
  for (const auto& [id, entry] : landmarks_)
    if (!entry.fixed)
      free_blocks[id] = {entry.block.data(), entry.minimal_size};
  return free_blocks;
}

std::map<int, Eigen::MatrixXd> BatchProblem::landmarkCovariances(
    const std::vector<std::pair<int, int>>& pairs,
    std::map<std::pair<int, int>, Eigen::MatrixXd>* cross) {
  return quadric_slam::landmarkCovariances(&problem_, freeLandmarkBlocks(), pairs, cross);
}

std::map<std::pair<int, int>, Eigen::MatrixXd> BatchProblem::landmarkCrossCovariances(
    const std::vector<std::pair<int, int>>& pairs) {
  return quadric_slam::landmarkCrossCovariances(&problem_, freeLandmarkBlocks(), pairs);
}

void BatchProblem::mergeLandmark(int merged, int survivor) {
  if (merged == survivor || !hasLandmark(merged) || !hasLandmark(survivor) ||
      landmarks_.at(merged).minimal_size != landmarks_.at(survivor).minimal_size)
    throw std::invalid_argument("BatchProblem::mergeLandmark: landmark " + std::to_string(merged) +
                                " cannot be merged into " + std::to_string(survivor));
  for (Term& term : terms_) {
    if (term.landmark_id != merged)
      continue;
    term.landmark_id = survivor;
    addTermBlock(&term);
  }
  problem_.RemoveParameterBlock(landmarks_.at(merged).block.data());
  landmarks_.erase(merged);
}

std::vector<double> BatchProblem::residualNorms() const {
  std::vector<double> norms;
  norms.reserve(terms_.size());
  Eigen::VectorXd r;
  for (const Term& term : terms_)
    if (whitenedResidual(problem_, term.block, &r))
      norms.push_back(r.norm());
  std::sort(norms.begin(), norms.end());
  return norms;
}

}  // namespace quadric_slam
