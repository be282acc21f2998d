#include "quadric_slam/mapping/batch_refiner.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "quadric_slam/mapping/batch_problem.h"
#include "quadric_slam/mapping/landmark_merger.h"

namespace quadric_slam {

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The refined estimates of the landmarks with a block in `problem` (a landmark whose block is no
// valid quadric keeps its previous estimate, counted), with compute_covariance their covariances;
// and the cross-covariances of the pairs among them whose extents touch, for the merger's test
// (from the covariances' factorisation when there is one).
void takeEstimates(bool compute_covariance, const LandmarkMerger& merger, BatchProblem* problem,
                   std::map<int, QuadricLandmark>* landmarks, CrossCovariances* cross,
                   BatchStatistics* stats) {
  stats->invalid_landmarks = 0;
  std::set<int> refined;  // free landmarks with a valid refined estimate
  std::map<int, QuadricLandmark> solved;
  for (auto& [id, landmark] : *landmarks) {
    if (!problem->hasLandmark(id))
      continue;
    if (!problem->landmarkFixed(id)) {
      try {
        landmark.quadric_map = problem->landmarkEstimate(id, landmark.quadric_map);
        refined.insert(id);
      } catch (const std::invalid_argument&) {
        ++stats->invalid_landmarks;
      }
    }
    solved.emplace(id, landmark);
  }
  const std::vector<std::pair<int, int>> pairs = merger.nearPairs(solved);
  const auto start = std::chrono::steady_clock::now();
  std::map<int, Eigen::MatrixXd> covariances;
  if (compute_covariance)
    covariances = problem->landmarkCovariances(pairs, cross);
  else
    *cross = problem->landmarkCrossCovariances(pairs);
  stats->covariance_computed = !covariances.empty();
  stats->covariance_seconds += secondsSince(start);
  for (auto& [id, landmark] : *landmarks) {
    const auto c = covariances.find(id);
    if (c != covariances.end() && refined.count(id) > 0)
      landmark.covariance = c->second;
  }
}

// The pairs of refined landmarks (those with a block) that are the same surface, tested with their
// cross-covariances in the problem (mapping/landmark_merger.h), by increasing d^2.
std::vector<DuplicatePair> duplicatesIn(const LandmarkMerger& merger, const BatchProblem& problem,
                                        const std::map<int, QuadricLandmark>& landmarks,
                                        const CrossCovariances& cross) {
  std::map<int, QuadricLandmark> solved;
  for (const auto& [id, landmark] : landmarks)
    if (problem.hasLandmark(id))
      solved.emplace(id, landmark);
  return merger.findDuplicates(solved, nullptr, &cross);
}

// One pass of merges of `pairs`, applied to the problem (the survivor's block at the fused
// estimate, the merged one's observations on it) and to `landmarks`. A landmark takes part in one
// merge per pass: the covariances the pairs were found with hold until the next solve.
std::vector<LandmarkMerge> mergePass(const LandmarkMerger& merger,
                                     const std::vector<DuplicatePair>& pairs,
                                     const CrossCovariances& cross, BatchProblem* problem,
                                     std::map<int, QuadricLandmark>* landmarks) {
  std::vector<LandmarkMerge> merges;
  std::set<int> touched;
  for (const DuplicatePair& pair : pairs) {
    if (touched.count(pair.id_a) > 0 || touched.count(pair.id_b) > 0)
      continue;
    const auto cross_ab = cross.find({pair.id_a, pair.id_b});
    LandmarkMerge merge;
    const std::optional<QuadricLandmark> survivor =
        merger.mergePair(landmarks->at(pair.id_a), problem->landmarkFixed(pair.id_a),
                         landmarks->at(pair.id_b), problem->landmarkFixed(pair.id_b), &merge,
                         cross_ab == cross.end() ? nullptr : &cross_ab->second);
    if (!survivor)
      continue;
    touched.insert(pair.id_a);
    touched.insert(pair.id_b);
    if (!problem->landmarkFixed(merge.survivor_id))
      problem->setLandmarkEstimate(merge.survivor_id, survivor->quadric_map);
    problem->mergeLandmark(merge.merged_id, merge.survivor_id);
    (*landmarks)[merge.survivor_id] = *survivor;
    landmarks->erase(merge.merged_id);
    merges.push_back(merge);
  }
  return merges;
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
  if (merge_rounds < 0 || merge_rounds > 10)
    throw std::invalid_argument("BatchRefiner::Params::merge_rounds must be in [0, 10]");
}

BatchRefiner::BatchRefiner(const Params& params) : params_(params) {
  params_.validate();
}

BatchSolution BatchRefiner::refine(const BatchRecorder& recorder,
                                   const QuadricMapper& mapper) const {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<RecordedKeyframe>& keyframes = recorder.keyframes();
  BatchSolution solution;
  BatchStatistics& stats = solution.statistics;
  stats.keyframes = static_cast<int>(keyframes.size());
  stats.frames = static_cast<int>(recorder.frames().size());
  for (const RecordedKeyframe& keyframe : keyframes)
    solution.keyframe_poses.push_back(keyframe.T_map_camera);
  auto online = [&] {
    solution.landmarks.clear();
    for (const auto& [id, landmark] : mapper.map().landmarks())
      solution.landmarks.push_back(landmark);
    solution.merges.clear();
    solution.duplicates.clear();
    solution.trajectory = reattachFrames(recorder, solution.keyframe_poses);
    stats.solve_seconds = secondsSince(start) - stats.covariance_seconds;
    return solution;
  };
  if (keyframes.empty() || stats.keyframes > params_.max_keyframes) {
    if (!keyframes.empty())
      stats.report = std::to_string(stats.keyframes) + " keyframes, more than max_keyframes " +
                     std::to_string(params_.max_keyframes) + ": not solved";
    return online();
  }

  BatchProblem problem(recorder, mapper, &stats);
  stats.solution_usable = problem.solve(params_, &stats);
  if (!stats.solution_usable)
    return online();
  std::map<int, QuadricLandmark> landmarks = mapper.map().landmarks();
  const LandmarkMerger& merger = mapper.map().merger();
  CrossCovariances cross;
  takeEstimates(params_.compute_covariance, merger, &problem, &landmarks, &cross, &stats);

  // Each surface once: refined surfaces, under honest covariances, may turn out to be one; merged,
  // and the problem solved again with their observations on one landmark.
  for (int pass = 0;; ++pass) {
    solution.duplicates = duplicatesIn(merger, problem, landmarks, cross);
    if (solution.duplicates.empty() || pass == params_.merge_rounds || !merger.params().enabled)
      break;
    const std::vector<LandmarkMerge> merges =
        mergePass(merger, solution.duplicates, cross, &problem, &landmarks);
    if (merges.empty())
      break;
    solution.merges.insert(solution.merges.end(), merges.begin(), merges.end());
    stats.solution_usable = problem.solve(params_, &stats);
    if (!stats.solution_usable)
      return online();
    takeEstimates(params_.compute_covariance, merger, &problem, &landmarks, &cross, &stats);
  }
  stats.merged_landmarks = static_cast<int>(solution.merges.size());

  for (std::size_t i = 0; i < keyframes.size(); ++i)
    solution.keyframe_poses[i] = problem.keyframePose(i);
  const std::vector<double> norms = problem.residualNorms();
  if (!norms.empty()) {
    stats.observation_residual_median = norms[norms.size() / 2];
    stats.observation_residual_p95 = norms[std::min(norms.size() - 1, norms.size() * 95 / 100)];
  }
  // A landmark that no keyframe observes (all its observations made on frames between keyframes)
  // has no block: the batch can neither refine it nor test it against the other landmarks, so the
  // refined map leaves it out (as keyframe-based SLAM culls map points seen from too few
  // keyframes).
  for (const auto& [id, landmark] : landmarks) {
    if (problem.hasLandmark(id))
      solution.landmarks.push_back(landmark);
    else
      ++stats.unobserved_landmarks;
  }
  solution.trajectory = reattachFrames(recorder, solution.keyframe_poses);
  stats.solve_seconds = secondsSince(start) - stats.covariance_seconds;
  return solution;
}

}  // namespace quadric_slam
