#include "quadric_slam/mapping/window.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <list>
#include <memory>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/observation_linearization.h"
#include "quadric_slam/mapping/solver_setup.h"
#include "quadric_slam/mapping/surface_fusion.h"
#include "quadric_slam/types/param_checks.h"

namespace quadric_slam {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using PoseBlock = std::array<double, kPoseParameterSize>;
using QuadricBlock = std::array<double, kQuadricParameterSize>;

}  // namespace

void SlidingWindow::Params::validate() const {
  const ParamRangeCheck requireRange("SlidingWindow::Params");
  requireRange(size >= 2 && size <= 1000, "size", "[2, 1000]");
  requireRange(max_iterations >= 1 && max_iterations <= 1000, "max_iterations", "[1, 1000]");
  requireRange(observation_huber >= 0.0, "observation_huber", "[0, inf)");
  requireRange(oldest_pose_translation_sigma > 0.0, "oldest_pose_translation_sigma", "(0, inf) m");
  requireRange(oldest_pose_rotation_sigma > 0.0, "oldest_pose_rotation_sigma", "(0, inf) rad");
  requireRange(landmark_prior_inflation >= 1.0, "landmark_prior_inflation", "[1, inf)");
}

SlidingWindow::SlidingWindow(const Params& params) : params_(params) {
  params_.validate();
}

void SlidingWindow::countObservation(int landmark_id) {
  ++observation_counts_[landmark_id];
}

void SlidingWindow::setLandmarkFixed(int landmark_id, bool fixed) {
  if (fixed)
    fixed_landmarks_.insert(landmark_id);
  else
    fixed_landmarks_.erase(landmark_id);
}

void SlidingWindow::foldIntoPrior(const Keyframe& keyframe, const WindowObservation& observation,
                                  const LandmarkRegistry& map) {
  if (landmarkFixed(observation.landmark_id))
    return;  // a constant block needs no prior
  const QuadricModel& landmark = map.landmark(observation.landmark_id).quadric_map;
  const ObservationLinearization lin =
      linearizeObservation(observation.measurement.quadric_camera, keyframe.T_map_camera, landmark);
  if (!lin.valid)
    return;
  // The leaving pose is uncertain by the oldest-pose prior: S = Sigma_z + J_c P J_c^T.
  const double st = params_.oldest_pose_translation_sigma;
  const double sr = params_.oldest_pose_rotation_sigma;
  const Vector6d p_diagonal =
      (Vector6d() << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr).finished();
  Eigen::MatrixXd S = observation.measurement.covariance +
                      lin.J_camera * p_diagonal.asDiagonal() * lin.J_camera.transpose();
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<Eigen::MatrixXd> llt(S);
  if (llt.info() != Eigen::Success)
    return;
  const Eigen::MatrixXd information = lin.J_quadric.transpose() * llt.solve(lin.J_quadric);
  if (!information.allFinite())
    return;
  LandmarkPrior& prior = priors_[observation.landmark_id];
  // Mean: the landmark's current estimate; information: the sum (both in its minimal tangent).
  prior.quadric_map = landmark;
  if (prior.information.size() == 0)
    prior.information = Eigen::MatrixXd::Zero(information.rows(), information.cols());
  prior.information += 0.5 * (information + information.transpose());
}

void SlidingWindow::dropFront() {
  for (const WindowObservation& observation : keyframes_.front().observations) {
    auto it = observation_counts_.find(observation.landmark_id);
    if (--it->second == 0)
      observation_counts_.erase(it);
  }
  keyframes_.pop_front();
  first_keyframe_in_window_ = false;
}

void SlidingWindow::addKeyframe(Keyframe keyframe, const LandmarkRegistry& map) {
  if (!any_keyframe_)
    any_keyframe_ = first_keyframe_in_window_ = true;
  for (const WindowObservation& observation : keyframe.observations)
    countObservation(observation.landmark_id);
  keyframes_.push_back(std::move(keyframe));
  if (params_.schur_marginalization)
    return;  // the next optimize() marginalises what is over the size
  while (static_cast<int>(keyframes_.size()) > params_.size) {
    for (const WindowObservation& observation : keyframes_.front().observations)
      foldIntoPrior(keyframes_.front(), observation, map);
    dropFront();
  }
}

bool SlidingWindow::addObservation(int frame_index, const WindowObservation& observation) {
  for (Keyframe& keyframe : keyframes_) {
    if (keyframe.frame_index == frame_index) {
      countObservation(observation.landmark_id);
      keyframe.observations.push_back(observation);
      return true;
    }
  }
  return false;
}

// One optimisation problem and what the marginalisation needs to know about its blocks.
struct SlidingWindow::Problem {
  Problem() : problem(options()) {}
  static ceres::Problem::Options options() {
    ceres::Problem::Options o;
    o.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    o.enable_fast_removal = true;  // keyframes and landmarks are removed when marginalised
    return o;
  }
  PoseManifold pose_manifold;
  std::map<QuadricClass, std::unique_ptr<QuadricManifold>> quadric_manifolds;
  std::unique_ptr<ceres::LossFunction> huber;
  ceres::Problem problem;
  std::list<PoseBlock> poses;                        // front = oldest keyframe (stable addresses)
  std::map<int, QuadricBlock> landmarks;             // landmark id -> block
  std::map<const double*, PriorVariable> variables;  // every pose and landmark block
  ceres::ResidualBlockId marginal_prior = nullptr;
  PoseBlock identity{};  // the constant pose of landmark priors

  QuadricManifold* manifold(QuadricClass c) {
    auto& m = quadric_manifolds[c];
    if (!m)
      m = std::make_unique<QuadricManifold>(c);
    return m.get();
  }
  double* block(const PriorVariable& v) {
    if (v.kind == PriorVariable::Kind::kLandmark) {
      auto it = landmarks.find(v.id);
      return it == landmarks.end() ? nullptr : it->second.data();
    }
    for (PoseBlock& pose : poses)
      if (variables.at(pose.data()).id == v.id)
        return pose.data();
    return nullptr;
  }
  // Adds the marginalisation prior; false when one of its variables has no block here.
  bool addPrior(const LinearizedPrior& prior) {
    std::vector<double*> blocks;
    for (const PriorVariable& v : prior.variables) {
      double* b = block(v);
      if (b == nullptr)
        return false;
      blocks.push_back(b);
    }
    marginal_prior = problem.AddResidualBlock(new LinearizedPriorCost(prior), nullptr, blocks);
    return true;
  }
};

WindowStatistics SlidingWindow::optimize(LandmarkRegistry* map) {
  last_ = WindowStatistics{};
  if (keyframes_.empty())
    return last_;
  Problem P;
  ceres::Problem& problem = P.problem;
  if (params_.observation_huber > 0.0)
    P.huber = std::make_unique<ceres::HuberLoss>(params_.observation_huber);

  // Poses, the gauge, odometry.
  const int n = static_cast<int>(keyframes_.size());
  std::vector<double*> poses(n);
  for (int i = 0; i < n; ++i) {
    P.poses.emplace_back();
    poses[i] = P.poses.back().data();
    poseToParameters(keyframes_[i].T_map_camera, poses[i]);
    problem.AddParameterBlock(poses[i], kPoseParameterSize, &P.pose_manifold);
    PriorVariable v;
    v.kind = PriorVariable::Kind::kPose;
    v.id = keyframes_[i].frame_index;
    P.variables[poses[i]] = v;
  }
  for (int i = 1; i < n; ++i) {
    problem.AddResidualBlock(
        RelativePoseCost::Create(keyframes_[i].T_previous_this, keyframes_[i].increment_covariance),
        nullptr, poses[i - 1], poses[i]);
    ++last_.odometry_factors;
  }

  // Landmarks and their observations.
  auto landmarkBlock = [&](int id) -> double* {
    auto it = P.landmarks.find(id);
    if (it != P.landmarks.end())
      return it->second.data();
    const QuadricModel& quadric = map->landmark(id).quadric_map;
    double* block = P.landmarks[id].data();
    quadricToParameters(quadric, block);
    problem.AddParameterBlock(block, kQuadricParameterSize, P.manifold(quadric.quadricClass()));
    if (landmarkFixed(id))
      problem.SetParameterBlockConstant(block);
    PriorVariable v;
    v.kind = PriorVariable::Kind::kLandmark;
    v.id = id;
    v.quadric_class = quadric.quadricClass();
    P.variables[block] = v;
    return block;
  };
  for (int i = 0; i < n; ++i) {
    for (const WindowObservation& observation : keyframes_[i].observations) {
      double* block = landmarkBlock(observation.landmark_id);
      problem.AddResidualBlock(
          QuadricObservationCost::Create(observation.measurement.quadric_camera,
                                         observation.measurement.covariance),
          P.huber.get(), poses[i], block);
      ++last_.observation_factors;
    }
  }

  // The gauge: the map's first keyframe, else the marginalisation prior, else a pose prior.
  bool gauge = false;
  if (first_keyframe_in_window_) {
    problem.SetParameterBlockConstant(poses[0]);
    gauge = true;
  }
  if (params_.schur_marginalization && !marginal_prior_.empty()) {
    // Every landmark of the prior is normally observed in the window (a landmark is eliminated
    // with its last observing keyframe, and a merged one is eliminated from the prior); a block
    // is added anyway so that the prior always finds its variables.
    for (const PriorVariable& v : marginal_prior_.variables)
      if (v.kind == PriorVariable::Kind::kLandmark && map->landmarks().count(v.id) > 0)
        landmarkBlock(v.id);
    if (P.addPrior(marginal_prior_)) {
      ++last_.marginalization_priors;
      gauge = true;
    }
  }
  if (!gauge) {
    const double st = params_.oldest_pose_translation_sigma;
    const double sr = params_.oldest_pose_rotation_sigma;
    const Matrix6d prior_covariance =
        (Vector6d() << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr)
            .finished()
            .asDiagonal();
    problem.AddResidualBlock(PosePriorCost::Create(keyframes_[0].T_map_camera, prior_covariance),
                             nullptr, poses[0]);
    ++last_.pose_priors;
  }

  poseToParameters(Eigen::Isometry3d::Identity(), P.identity.data());
  for (const auto& [id, prior] : priors_) {
    if (P.landmarks.count(id) == 0 || landmarkFixed(id))
      continue;
    const Eigen::LLT<Eigen::MatrixXd> information(prior.information);
    if (information.info() != Eigen::Success)
      continue;
    const Eigen::MatrixXd prior_covariance =
        params_.landmark_prior_inflation * information.solve(Eigen::MatrixXd::Identity(
                                               prior.information.rows(), prior.information.cols()));
    if (last_.landmark_priors == 0) {
      problem.AddParameterBlock(P.identity.data(), kPoseParameterSize, &P.pose_manifold);
      problem.SetParameterBlockConstant(P.identity.data());
    }
    problem.AddResidualBlock(
        QuadricObservationCost::Create(prior.quadric_map,
                                       0.5 * (prior_covariance + prior_covariance.transpose())),
        nullptr, P.identity.data(), P.landmarks.at(id).data());
    ++last_.landmark_priors;
  }

  last_.keyframes = n;
  last_.pose_blocks = n;
  last_.landmark_blocks = static_cast<int>(P.landmarks.size());
  last_.parameter_blocks = problem.NumParameterBlocks();
  last_.residual_blocks = problem.NumResidualBlocks();
  last_.residuals = problem.NumResiduals();

  const ceres::Solver::Options options = windowSolverOptions(params_.max_iterations, n);
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  last_.iterations = static_cast<int>(summary.iterations.size());
  last_.initial_cost = summary.initial_cost;
  last_.final_cost = summary.final_cost;
  last_.solution_usable = summary.IsSolutionUsable();
  if (last_.solution_usable)
    writeBack(&P, poses, map);
  else
    resetBlocks(&P, poses, *map);  // marginalise at the estimates the window started from

  if (params_.schur_marginalization) {
    while (static_cast<int>(keyframes_.size()) > params_.size) {
      marginalizeOldest(&P, *map);
      ++last_.marginalized_keyframes;
    }
    last_.marginal_prior_rows = static_cast<int>(marginal_prior_.J.rows());
  }
  return last_;
}

void SlidingWindow::resetBlocks(Problem* P, const std::vector<double*>& poses,
                                const LandmarkRegistry& map) {
  for (std::size_t i = 0; i < poses.size(); ++i)
    poseToParameters(keyframes_[i].T_map_camera, poses[i]);
  for (auto& [id, block] : P->landmarks)
    quadricToParameters(map.landmark(id).quadric_map, block.data());
}

void SlidingWindow::writeBack(Problem* P, const std::vector<double*>& poses,
                              LandmarkRegistry* map) {
  ceres::Problem& problem = P->problem;
  for (std::size_t i = 0; i < poses.size(); ++i)
    keyframes_[i].T_map_camera = poseFromParameters(poses[i]);

  // Fixed landmarks keep their estimates and covariances: only the free ones are written back.
  std::vector<int> free_landmarks;
  for (const auto& [id, block] : P->landmarks)
    if (!landmarkFixed(id))
      free_landmarks.push_back(id);
  std::map<int, LandmarkBlock> free_blocks;
  for (int id : free_landmarks)
    free_blocks[id] = {P->landmarks.at(id).data(),
                       minimalDimension(map->landmark(id).quadric_map.quadricClass())};
  std::map<int, Eigen::MatrixXd> covariances;
  if (params_.compute_covariance)
    covariances = landmarkCovariances(&problem, free_blocks);
  for (int id : free_landmarks) {
    const QuadricModel& old = map->landmark(id).quadric_map;
    double* block = P->landmarks.at(id).data();
    try {
      const QuadricModel updated =
          quadricFromParameters(block, old.quadricClass(), old.signature());
      auto it = covariances.find(id);
      map->setEstimate(id, updated, it != covariances.end() ? it->second : Eigen::MatrixXd());
    } catch (const std::invalid_argument&) {
      // An invalid estimate (e.g. a scale pushed through zero): keep the previous one, also as
      // the linearisation point of a marginalisation.
      quadricToParameters(old, block);
    }
  }
}

void SlidingWindow::marginalizeOldest(Problem* P, const LandmarkRegistry& map) {
  ceres::Problem& problem = P->problem;
  const Keyframe& leaving = keyframes_.front();
  double* leaving_pose = P->poses.front().data();

  // The landmarks only the leaving keyframe observes leave with it.
  std::map<int, int> leaving_counts;
  for (const WindowObservation& observation : leaving.observations)
    ++leaving_counts[observation.landmark_id];
  std::vector<double*> eliminated_blocks = {leaving_pose};
  std::vector<int> leaving_landmarks;
  for (const auto& [id, count] : leaving_counts) {
    if (observation_counts_.at(id) != count)
      continue;
    leaving_landmarks.push_back(id);
    eliminated_blocks.push_back(P->landmarks.at(id).data());
  }
  // A landmark of the prior alone (no window observation left) leaves too.
  for (const auto& [id, block] : P->landmarks)
    if (observation_counts_.count(id) == 0 &&
        std::find(leaving_landmarks.begin(), leaving_landmarks.end(), id) ==
            leaving_landmarks.end()) {
      leaving_landmarks.push_back(id);
      eliminated_blocks.push_back(const_cast<double*>(block.data()));
    }

  // Every factor that touches an eliminated variable (the previous prior touches the oldest
  // pose, or is replaced anyway).
  std::set<ceres::ResidualBlockId> residuals;
  for (double* block : eliminated_blocks) {
    std::vector<ceres::ResidualBlockId> ids;
    problem.GetResidualBlocksForParameterBlock(block, &ids);
    residuals.insert(ids.begin(), ids.end());
  }
  if (P->marginal_prior != nullptr)
    residuals.insert(P->marginal_prior);

  // Their variables (constant blocks are known, not variables): eliminated ones first.
  std::vector<const double*> order;
  std::vector<bool> eliminate;
  std::map<const double*, int> column_of;
  int columns = 0, rows = 0;
  auto addVariable = [&](const double* block, bool eliminated) {
    if (column_of.count(block) > 0 || problem.IsParameterBlockConstant(block))
      return;
    column_of[block] = columns;
    columns += problem.ParameterBlockTangentSize(block);
    order.push_back(block);
    eliminate.push_back(eliminated);
  };
  for (double* block : eliminated_blocks)
    addVariable(block, true);
  for (ceres::ResidualBlockId id : residuals) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(id, &blocks);
    for (double* block : blocks)
      addVariable(block, false);
    rows += problem.GetCostFunctionForResidualBlock(id)->num_residuals();
  }

  // The stacked, robustified Jacobian in the tangent spaces and the residuals at the estimate.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, columns);
  Eigen::VectorXd r = Eigen::VectorXd::Zero(rows);
  int row = 0;
  for (ceres::ResidualBlockId id : residuals) {
    std::vector<double*> blocks;
    problem.GetParameterBlocksForResidualBlock(id, &blocks);
    const int m = problem.GetCostFunctionForResidualBlock(id)->num_residuals();
    std::vector<RowMajor> jacobians(blocks.size());
    std::vector<double*> jacobian_pointers(blocks.size(), nullptr);
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      if (column_of.count(blocks[b]) == 0)
        continue;
      jacobians[b].resize(m, problem.ParameterBlockTangentSize(blocks[b]));
      jacobian_pointers[b] = jacobians[b].data();
    }
    double cost = 0.0;
    Eigen::VectorXd residual(m);
    if (problem.EvaluateResidualBlock(id, true, &cost, residual.data(), jacobian_pointers.data()) &&
        residual.allFinite()) {
      r.segment(row, m) = residual;
      for (std::size_t b = 0; b < blocks.size(); ++b)
        if (jacobian_pointers[b] != nullptr && jacobians[b].allFinite())
          A.block(row, column_of.at(blocks[b]), m, jacobians[b].cols()) = jacobians[b];
    }
    row += m;
  }
  std::vector<PriorVariable> variables;
  for (const double* block : order) {
    PriorVariable v = P->variables.at(block);
    std::copy(block, block + v.ambientSize(), v.x0.begin());
    variables.push_back(v);
  }
  marginal_prior_ =
      schurComplementPrior(variables, eliminate, A.transpose() * A, A.transpose() * r);

  // A landmark leaving the window keeps its estimate in the map; seen again, it re-enters with a
  // prior from its covariance there.
  for (int id : leaving_landmarks) {
    if (landmarkFixed(id) || map.landmarks().count(id) == 0)
      continue;
    const QuadricLandmark& landmark = map.landmark(id);
    if (landmark.covariance.size() == 0)
      continue;
    const Eigen::LLT<Eigen::MatrixXd> llt(landmark.covariance);
    if (llt.info() != Eigen::Success)
      continue;
    const Eigen::MatrixXd information = llt.solve(
        Eigen::MatrixXd::Identity(landmark.covariance.rows(), landmark.covariance.cols()));
    priors_[id] = {landmark.quadric_map, 0.5 * (information + information.transpose())};
  }

  // The eliminated variables leave the problem with their factors; the new prior replaces the old.
  for (double* block : eliminated_blocks)
    problem.RemoveParameterBlock(block);
  if (P->marginal_prior != nullptr && residuals.count(P->marginal_prior) > 0) {
    // Removed with the oldest pose unless the prior did not touch it.
    std::vector<ceres::ResidualBlockId> all;
    problem.GetResidualBlocks(&all);
    if (std::find(all.begin(), all.end(), P->marginal_prior) != all.end())
      problem.RemoveResidualBlock(P->marginal_prior);
  }
  P->marginal_prior = nullptr;
  for (int id : leaving_landmarks)
    P->landmarks.erase(id);
  P->poses.pop_front();
  dropFront();
  if (!marginal_prior_.empty() && !P->addPrior(marginal_prior_))
    marginal_prior_ = {};
}

void SlidingWindow::mergeLandmark(int merged_id, int survivor_id,
                                  const QuadricModel& survivor_estimate) {
  if (merged_id == survivor_id)
    return;
  for (Keyframe& keyframe : keyframes_)
    for (WindowObservation& observation : keyframe.observations)
      if (observation.landmark_id == merged_id)
        observation.landmark_id = survivor_id;
  auto count = observation_counts_.find(merged_id);
  if (count != observation_counts_.end()) {
    observation_counts_[survivor_id] += count->second;
    observation_counts_.erase(count);
  }
  if (fixed_landmarks_.erase(merged_id) > 0)
    fixed_landmarks_.insert(survivor_id);
  const int in_prior = marginal_prior_.find(PriorVariable::Kind::kLandmark, merged_id);
  if (in_prior >= 0)
    marginal_prior_ = eliminateVariable(marginal_prior_, static_cast<std::size_t>(in_prior));
  auto merged_prior = priors_.find(merged_id);
  if (merged_prior == priors_.end())
    return;
  auto survivor_prior = priors_.find(survivor_id);
  if (survivor_prior == priors_.end()) {
    // Only the merged landmark had folded observations: they are a prior on the survivor now,
    // expressed near the survivor's frame (later folds add information in that frame).
    const AlignedSurface aligned = alignInformation(
        merged_prior->second.quadric_map, merged_prior->second.information, survivor_estimate);
    priors_[survivor_id] = {aligned.quadric, aligned.matrix};
  } else {
    const SurfaceInformation fused =
        fuseSurfaces({survivor_prior->second.quadric_map, survivor_prior->second.information},
                     {merged_prior->second.quadric_map, merged_prior->second.information});
    survivor_prior->second = {fused.mean, fused.information};
  }
  priors_.erase(merged_id);
}

std::set<int> SlidingWindow::landmarkIds() const {
  std::set<int> ids;
  for (const auto& [id, count] : observation_counts_)
    ids.insert(id);
  return ids;
}

void SlidingWindow::clear() {
  keyframes_.clear();
  observation_counts_.clear();
  priors_.clear();
  marginal_prior_ = {};
  fixed_landmarks_.clear();
  first_keyframe_in_window_ = any_keyframe_ = false;
  last_ = WindowStatistics{};
}

}  // namespace quadric_slam
