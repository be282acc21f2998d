#include "quadric_slam/mapping/batch_refiner.h"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <vector>

#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/observation_noise_scale.h"
#include "quadric_slam/mapping/solver_setup.h"

namespace quadric_slam {

namespace {

using PoseBlock = std::array<double, kPoseParameterSize>;
using QuadricBlock = std::array<double, kQuadricParameterSize>;

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// One keyframe's observation of a landmark, and its residual block in the problem.
struct ObservationTerm {
  double* pose = nullptr;
  double* landmark = nullptr;
  const QuadricMeasurement* measurement = nullptr;
  ceres::ResidualBlockId block = nullptr;
};

// (Re)adds every observation with its covariance times the variance factor.
void addObservationBlocks(double factor, ceres::LossFunction* loss, ceres::Problem* problem,
                          std::vector<ObservationTerm>* terms) {
  for (ObservationTerm& term : *terms) {
    if (term.block != nullptr)
      problem->RemoveResidualBlock(term.block);
    term.block = problem->AddResidualBlock(
        QuadricObservationCost::Create(term.measurement->quadric_camera,
                                       term.measurement->covariance * factor),
        loss, term.pose, term.landmark);
  }
}

// The whitened residual of an observation (before the robust loss) under the covariance its block
// carries; false when it cannot be evaluated.
bool whitenedResidual(const ceres::Problem& problem, const ObservationTerm& term,
                      Eigen::VectorXd* r) {
  r->resize(problem.GetCostFunctionForResidualBlock(term.block)->num_residuals());
  double cost = 0.0;
  return problem.EvaluateResidualBlock(term.block, false, &cost, r->data(), nullptr) &&
         r->allFinite();
}

// The variance factor the residuals at the current parameters call for; `current` is the factor
// the problem's blocks carry (residuals under the measured covariances are theirs scaled back).
double estimateFactor(const ceres::Problem& problem, const std::vector<ObservationTerm>& terms,
                      double current) {
  std::vector<WhitenedResidual> residuals;
  residuals.reserve(terms.size());
  Eigen::VectorXd r;
  for (const ObservationTerm& term : terms)
    if (whitenedResidual(problem, term, &r))
      residuals.push_back({static_cast<int>(r.size()), r.squaredNorm() * current});
  return observationVarianceFactor(residuals);
}

}  // namespace

void BatchRefiner::Params::validate() const {
  if (max_iterations < 1 || max_iterations > 10000)
    throw std::invalid_argument("BatchRefiner::Params::max_iterations must be in [1, 10000]");
  if (max_keyframes < 1 || max_keyframes > 1000000)
    throw std::invalid_argument("BatchRefiner::Params::max_keyframes must be in [1, 1000000]");
  if (noise_rounds < 0 || noise_rounds > 10)
    throw std::invalid_argument("BatchRefiner::Params::noise_rounds must be in [0, 10]");
  if (!(noise_tolerance > 0.0 && noise_tolerance <= 10.0))
    throw std::invalid_argument("BatchRefiner::Params::noise_tolerance must be in (0, 10]");
}

BatchRefiner::BatchRefiner(const Params& params) : params_(params) {
  params_.validate();
}

std::vector<RefinedPose> reattachFrames(const BatchRecorder& recorder,
                                        const std::vector<Eigen::Isometry3d>& keyframe_poses) {
  if (keyframe_poses.size() != recorder.keyframes().size())
    throw std::invalid_argument("reattachFrames: one pose per recorded keyframe is needed");
  std::vector<RefinedPose> out;
  out.reserve(recorder.frames().size());
  for (const RecordedFrame& frame : recorder.frames()) {
    RefinedPose pose{frame.stamp, frame.T_map_camera};
    if (frame.keyframe >= 0) {
      const RecordedKeyframe& keyframe = recorder.keyframes()[frame.keyframe];
      // The mapper's prediction (quadric_mapper.h, step 1) from the refined keyframe pose.
      pose.T_map_camera =
          keyframe_poses[frame.keyframe] * keyframe.T_odom_camera.inverse() * frame.T_odom_camera;
    }
    out.push_back(pose);
  }
  return out;
}

BatchSolution BatchRefiner::refine(const BatchRecorder& recorder,
                                   const QuadricMapper& mapper) const {
  const auto start = std::chrono::steady_clock::now();
  const LandmarkRegistry& map = mapper.map();
  const SlidingWindow& window = mapper.window();
  const std::vector<RecordedKeyframe>& keyframes = recorder.keyframes();
  BatchSolution solution;
  BatchStatistics& stats = solution.statistics;
  stats.keyframes = static_cast<int>(keyframes.size());
  stats.frames = static_cast<int>(recorder.frames().size());
  for (const RecordedKeyframe& keyframe : keyframes)
    solution.keyframe_poses.push_back(keyframe.T_map_camera);
  for (const auto& [id, landmark] : map.landmarks())
    solution.landmarks.push_back(landmark);
  if (keyframes.empty() || stats.keyframes > params_.max_keyframes) {
    if (!keyframes.empty())
      stats.report = std::to_string(stats.keyframes) + " keyframes, more than max_keyframes " +
                     std::to_string(params_.max_keyframes) + ": not solved";
    solution.trajectory = reattachFrames(recorder, solution.keyframe_poses);
    return solution;
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  PoseManifold pose_manifold;
  std::map<QuadricClass, std::unique_ptr<QuadricManifold>> quadric_manifolds;
  std::unique_ptr<ceres::LossFunction> huber;
  // Landmarks held fixed one by one (a trusted, loaded map) stay constant; the window's
  // localisation-only mode (also set while recovering from a loss of tracking) is a mode of the
  // online estimation, not a property of the landmarks: the batch refines them.
  auto fixed = [&](int id) { return window.individuallyFixedLandmarks().count(id) > 0; };
  if (window.params().observation_huber > 0.0)
    huber = std::make_unique<ceres::HuberLoss>(window.params().observation_huber);

  // Poses, the gauge and the odometry chain.
  std::vector<PoseBlock> poses(keyframes.size());
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    poseToParameters(keyframes[i].T_map_camera, poses[i].data());
    problem.AddParameterBlock(poses[i].data(), kPoseParameterSize, &pose_manifold);
  }
  problem.SetParameterBlockConstant(poses[0].data());
  for (std::size_t i = 1; i < keyframes.size(); ++i) {
    problem.AddResidualBlock(
        RelativePoseCost::Create(keyframes[i].T_previous_this, keyframes[i].increment_covariance),
        nullptr, poses[i - 1].data(), poses[i].data());
    ++stats.odometry_factors;
  }

  // Landmarks and every keyframe observation of them.
  std::map<int, QuadricBlock> landmarks;
  std::vector<ObservationTerm> observations;
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    for (const WindowObservation& observation : keyframes[i].observations) {
      const int id = observation.landmark_id;
      if (map.landmarks().count(id) == 0) {
        ++stats.skipped_observations;
        continue;
      }
      auto it = landmarks.find(id);
      if (it == landmarks.end()) {
        it = landmarks.emplace(id, QuadricBlock{}).first;
        quadricToParameters(map.landmark(id).quadric_map, it->second.data());
        const QuadricClass quadric_class = map.landmark(id).quadric_map.quadricClass();
        auto& manifold = quadric_manifolds[quadric_class];
        if (!manifold)
          manifold = std::make_unique<QuadricManifold>(quadric_class);
        problem.AddParameterBlock(it->second.data(), kQuadricParameterSize, manifold.get());
        if (fixed(id)) {
          problem.SetParameterBlockConstant(it->second.data());
          ++stats.fixed_landmarks;
        }
      }
      observations.push_back({poses[i].data(), it->second.data(), &observation.measurement});
      ++stats.observation_factors;
    }
  }
  stats.landmarks = static_cast<int>(landmarks.size());
  double factor = 1.0;
  addObservationBlocks(factor, huber.get(), &problem, &observations);

  // The paper's batch solver: dog-leg; solved again while the observations' variance factor,
  // re-estimated at each solution, still changes.
  ceres::Solver::Options options = landmarkSolverOptions(params_.max_iterations);
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.dogleg_type = ceres::TRADITIONAL_DOGLEG;
  const int solves = std::max(1, params_.noise_rounds);
  for (int round = 0; round < solves; ++round) {
    if (params_.noise_rounds > 0) {
      const double estimated = estimateFactor(problem, observations, factor);
      if (round > 0 && std::abs(estimated / factor - 1.0) <= params_.noise_tolerance)
        break;
      factor = estimated;
      addObservationBlocks(factor, huber.get(), &problem, &observations);
    }
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    ++stats.solves;
    stats.iterations += static_cast<int>(summary.iterations.size());
    if (round == 0)
      stats.initial_cost = summary.initial_cost;
    stats.final_cost = summary.final_cost;
    stats.solution_usable = summary.IsSolutionUsable();
    stats.report = summary.BriefReport();
    if (!stats.solution_usable)
      break;
  }
  stats.observation_variance_factor = factor;
  stats.solve_seconds = secondsSince(start);
  if (!stats.solution_usable) {
    solution.trajectory = reattachFrames(recorder, solution.keyframe_poses);
    return solution;
  }

  for (std::size_t i = 0; i < keyframes.size(); ++i)
    solution.keyframe_poses[i] = poseFromParameters(poses[i].data());
  std::vector<double> norms;
  Eigen::VectorXd r;
  for (const ObservationTerm& term : observations)
    if (whitenedResidual(problem, term, &r))
      norms.push_back(r.norm());
  if (!norms.empty()) {
    std::sort(norms.begin(), norms.end());
    stats.observation_residual_median = norms[norms.size() / 2];
    stats.observation_residual_p95 = norms[std::min(norms.size() - 1, norms.size() * 95 / 100)];
  }
  std::map<int, LandmarkBlock> free_blocks;
  for (const auto& [id, block] : landmarks)
    if (!fixed(id))
      free_blocks[id] = {block.data(),
                         minimalDimension(map.landmark(id).quadric_map.quadricClass())};
  const auto covariance_start = std::chrono::steady_clock::now();
  std::map<int, Eigen::MatrixXd> covariances;
  if (params_.compute_covariance)
    covariances = landmarkCovariances(&problem, free_blocks);
  stats.covariance_computed = !covariances.empty();
  stats.covariance_seconds = secondsSince(covariance_start);
  for (QuadricLandmark& landmark : solution.landmarks) {
    if (landmarks.count(landmark.id) == 0 || fixed(landmark.id))
      continue;
    const QuadricModel& online = landmark.quadric_map;
    try {
      landmark.quadric_map = quadricFromParameters(landmarks.at(landmark.id).data(),
                                                   online.quadricClass(), online.signature());
    } catch (const std::invalid_argument&) {
      ++stats.invalid_landmarks;  // the online estimate stays
      continue;
    }
    const auto c = covariances.find(landmark.id);
    if (c != covariances.end())
      landmark.covariance = c->second;
  }
  solution.trajectory = reattachFrames(recorder, solution.keyframe_poses);
  return solution;
}

}  // namespace quadric_slam
