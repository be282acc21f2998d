#include "quadric_slam/mapping/window.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <array>
#include <memory>
#include <stdexcept>
#include <string>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/observation_linearization.h"
#include "quadric_slam/mapping/surface_fusion.h"

namespace quadric_slam {

namespace {

using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using PoseBlock = std::array<double, kPoseParameterSize>;
using QuadricBlock = std::array<double, kQuadricParameterSize>;

void requireRange(bool ok, const char* field, const char* range) {
  if (!ok)
    throw std::invalid_argument(std::string("SlidingWindow::Params::") + field + " must be in " +
                                range);
}

}  // namespace

void SlidingWindow::Params::validate() const {
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

void SlidingWindow::addKeyframe(Keyframe keyframe, const LandmarkRegistry& map) {
  if (!any_keyframe_)
    any_keyframe_ = first_keyframe_in_window_ = true;
  for (const WindowObservation& observation : keyframe.observations)
    countObservation(observation.landmark_id);
  keyframes_.push_back(std::move(keyframe));
  while (static_cast<int>(keyframes_.size()) > params_.size) {
    for (const WindowObservation& observation : keyframes_.front().observations) {
      foldIntoPrior(keyframes_.front(), observation, map);
      auto it = observation_counts_.find(observation.landmark_id);
      if (--it->second == 0)
        observation_counts_.erase(it);
    }
    keyframes_.pop_front();
    first_keyframe_in_window_ = false;
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

WindowStatistics SlidingWindow::optimize(LandmarkRegistry* map) {
  last_ = WindowStatistics{};
  if (keyframes_.empty())
    return last_;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  PoseManifold pose_manifold;
  std::map<QuadricClass, std::unique_ptr<QuadricManifold>> quadric_manifolds;
  std::unique_ptr<ceres::LossFunction> huber;
  if (params_.observation_huber > 0.0)
    huber = std::make_unique<ceres::HuberLoss>(params_.observation_huber);

  // Poses, the gauge, odometry.
  const int n = static_cast<int>(keyframes_.size());
  std::vector<PoseBlock> poses(n);
  for (int i = 0; i < n; ++i) {
    poseToParameters(keyframes_[i].T_map_camera, poses[i].data());
    problem.AddParameterBlock(poses[i].data(), kPoseParameterSize, &pose_manifold);
  }
  if (first_keyframe_in_window_) {
    problem.SetParameterBlockConstant(poses[0].data());
  } else {
    const double st = params_.oldest_pose_translation_sigma;
    const double sr = params_.oldest_pose_rotation_sigma;
    const Matrix6d prior_covariance =
        (Vector6d() << st * st, st * st, st * st, sr * sr, sr * sr, sr * sr)
            .finished()
            .asDiagonal();
    problem.AddResidualBlock(PosePriorCost::Create(keyframes_[0].T_map_camera, prior_covariance),
                             nullptr, poses[0].data());
    ++last_.pose_priors;
  }
  for (int i = 1; i < n; ++i) {
    problem.AddResidualBlock(
        RelativePoseCost::Create(keyframes_[i].T_previous_this, keyframes_[i].increment_covariance),
        nullptr, poses[i - 1].data(), poses[i].data());
    ++last_.odometry_factors;
  }

  // Landmarks and their observations.
  std::map<int, QuadricBlock> landmarks;
  auto landmarkBlock = [&](int id) -> double* {
    auto it = landmarks.find(id);
    if (it != landmarks.end())
      return it->second.data();
    const QuadricModel& quadric = map->landmark(id).quadric_map;
    QuadricBlock& block = landmarks[id];
    quadricToParameters(quadric, block.data());
    auto& manifold = quadric_manifolds[quadric.quadricClass()];
    if (!manifold)
      manifold = std::make_unique<QuadricManifold>(quadric.quadricClass());
    problem.AddParameterBlock(block.data(), kQuadricParameterSize, manifold.get());
    if (landmarkFixed(id))
      problem.SetParameterBlockConstant(block.data());
    return block.data();
  };
  for (int i = 0; i < n; ++i) {
    for (const WindowObservation& observation : keyframes_[i].observations) {
      double* block = landmarkBlock(observation.landmark_id);
      problem.AddResidualBlock(
          QuadricObservationCost::Create(observation.measurement.quadric_camera,
                                         observation.measurement.covariance),
          huber.get(), poses[i].data(), block);
      ++last_.observation_factors;
    }
  }
  PoseBlock identity;
  poseToParameters(Eigen::Isometry3d::Identity(), identity.data());
  for (const auto& [id, prior] : priors_) {
    if (landmarks.count(id) == 0 || landmarkFixed(id))
      continue;
    const Eigen::LLT<Eigen::MatrixXd> information(prior.information);
    if (information.info() != Eigen::Success)
      continue;
    const Eigen::MatrixXd prior_covariance =
        params_.landmark_prior_inflation * information.solve(Eigen::MatrixXd::Identity(
                                               prior.information.rows(), prior.information.cols()));
    if (last_.landmark_priors == 0) {
      problem.AddParameterBlock(identity.data(), kPoseParameterSize, &pose_manifold);
      problem.SetParameterBlockConstant(identity.data());
    }
    problem.AddResidualBlock(
        QuadricObservationCost::Create(prior.quadric_map,
                                       0.5 * (prior_covariance + prior_covariance.transpose())),
        nullptr, identity.data(), landmarks.at(id).data());
    ++last_.landmark_priors;
  }

  last_.keyframes = n;
  last_.pose_blocks = n;
  last_.landmark_blocks = static_cast<int>(landmarks.size());
  last_.parameter_blocks = problem.NumParameterBlocks();
  last_.residual_blocks = problem.NumResidualBlocks();
  last_.residuals = problem.NumResiduals();

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.max_num_iterations = params_.max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  last_.iterations = static_cast<int>(summary.iterations.size());
  last_.initial_cost = summary.initial_cost;
  last_.final_cost = summary.final_cost;
  last_.solution_usable = summary.IsSolutionUsable();
  if (!last_.solution_usable)
    return last_;

  for (int i = 0; i < n; ++i)
    keyframes_[i].T_map_camera = poseFromParameters(poses[i].data());

  // Fixed landmarks keep their estimates and covariances: only the free ones are written back.
  std::vector<int> free_landmarks;
  for (const auto& [id, block] : landmarks)
    if (!landmarkFixed(id))
      free_landmarks.push_back(id);
  std::map<int, Eigen::MatrixXd> covariances;
  if (params_.compute_covariance && !free_landmarks.empty()) {
    ceres::Covariance::Options covariance_options;
    covariance_options.algorithm_type = ceres::SPARSE_QR;
    covariance_options.num_threads = 1;
    ceres::Covariance covariance(covariance_options);
    std::vector<std::pair<const double*, const double*>> blocks;
    for (int id : free_landmarks)
      blocks.emplace_back(landmarks.at(id).data(), landmarks.at(id).data());
    if (covariance.Compute(blocks, &problem)) {
      for (int id : free_landmarks) {
        const double* block = landmarks.at(id).data();
        const int k = minimalDimension(map->landmark(id).quadric_map.quadricClass());
        RowMajor c(k, k);
        if (!covariance.GetCovarianceBlockInTangentSpace(block, block, c.data()) || !c.allFinite())
          continue;
        const Eigen::MatrixXd symmetric = 0.5 * (c + c.transpose());
        if (Eigen::LLT<Eigen::MatrixXd>(symmetric).info() == Eigen::Success)
          covariances[id] = symmetric;
      }
    }
  }
  for (int id : free_landmarks) {
    const QuadricModel& old = map->landmark(id).quadric_map;
    try {
      const QuadricModel updated =
          quadricFromParameters(landmarks.at(id).data(), old.quadricClass(), old.signature());
      auto it = covariances.find(id);
      map->setEstimate(id, updated, it != covariances.end() ? it->second : Eigen::MatrixXd());
    } catch (const std::invalid_argument&) {
      // An invalid estimate (e.g. a scale pushed through zero): keep the previous one.
    }
  }
  return last_;
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
  fixed_landmarks_.clear();
  first_keyframe_in_window_ = any_keyframe_ = false;
  last_ = WindowStatistics{};
}

}  // namespace quadric_slam
