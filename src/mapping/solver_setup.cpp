#include "quadric_slam/mapping/solver_setup.h"

#include "quadric_slam/mapping/schur_covariance.h"

#include <Eigen/Cholesky>
#include <utility>
#include <vector>

namespace quadric_slam {

namespace {

// Covariance blocks Cov(a, b) in the minimal tangents of the requested pairs of `landmarks` (ids)
// by ceres::Covariance (sparse QR of the whole problem), keyed by the pair; pairs with an unknown
// id, or whose block Ceres cannot give or gives non-finite, are left out, and all are when the
// problem is rank-deficient.
std::map<std::pair<int, int>, Eigen::MatrixXd> ceresCovarianceBlocks(
    ceres::Problem* problem, const std::map<int, LandmarkBlock>& landmarks,
    const std::vector<std::pair<int, int>>& pairs) {
  std::map<std::pair<int, int>, Eigen::MatrixXd> out;
  std::vector<std::pair<const double*, const double*>> blocks;
  std::vector<std::pair<int, int>> requested;
  for (const auto& [id_a, id_b] : pairs) {
    const auto a = landmarks.find(id_a), b = landmarks.find(id_b);
    if (a == landmarks.end() || b == landmarks.end())
      continue;
    blocks.emplace_back(a->second.parameters, b->second.parameters);
    requested.emplace_back(id_a, id_b);
  }
  if (blocks.empty())
    return out;
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::SPARSE_QR;
  options.num_threads = 1;
  ceres::Covariance covariance(options);
  if (!covariance.Compute(blocks, problem))
    return out;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (std::size_t i = 0; i < blocks.size(); ++i) {
    const LandmarkBlock& a = landmarks.at(requested[i].first);
    const LandmarkBlock& b = landmarks.at(requested[i].second);
    RowMajor c(a.minimal_size, b.minimal_size);
    if (covariance.GetCovarianceBlockInTangentSpace(blocks[i].first, blocks[i].second, c.data()) &&
        c.allFinite())
      out[requested[i]] = c;
  }
  return out;
}

// The pairs of two different landmarks among `pairs` (a pair of one landmark is its marginal).
std::vector<std::pair<int, int>> crossPairs(const std::vector<std::pair<int, int>>& pairs) {
  std::vector<std::pair<int, int>> distinct;
  for (const auto& pair : pairs)
    if (pair.first != pair.second)
      distinct.push_back(pair);
  return distinct;
}

}  // namespace

ceres::Solver::Options landmarkSolverOptions(int max_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.max_num_iterations = max_iterations;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  return options;
}

ceres::Solver::Options windowSolverOptions(int max_iterations, int pose_blocks) {
  ceres::Solver::Options options = landmarkSolverOptions(max_iterations);
  // Real kitchen, window of 10 keyframes (about 260 variables, 66 blocks once the landmarks are
  // eliminated): 18 ms per solve with dense Schur against 31 ms with sparse Schur, the same
  // trajectory. Up to 50 keyframes the reduced system stays below about 600 variables.
  constexpr int kMaxDensePoseBlocks = 50;
  if (pose_blocks <= kMaxDensePoseBlocks)
    options.linear_solver_type = ceres::DENSE_SCHUR;
  return options;
}

Eigen::MatrixXd acceptedCovariance(const Eigen::MatrixXd& covariance) {
  const Eigen::MatrixXd symmetric = 0.5 * (covariance + covariance.transpose());
  if (!symmetric.allFinite() || Eigen::LLT<Eigen::MatrixXd>(symmetric).info() != Eigen::Success)
    return Eigen::MatrixXd();
  return symmetric;
}

std::map<int, Eigen::MatrixXd> landmarkCovariances(
    ceres::Problem* problem, const std::map<int, LandmarkBlock>& landmarks,
    const std::vector<std::pair<int, int>>& pairs,
    std::map<std::pair<int, int>, Eigen::MatrixXd>* cross) {
  std::map<int, Eigen::MatrixXd> out;
  // A window's poses (and landmarks tied by its marginalisation prior) make a dense part of a few
  // dozen to a few hundred variables: the Schur complement on them is cheaper than a sparse QR of
  // the whole Jacobian (kitchen, 300 frames: 3.6 ms per keyframe solve against 9.1 ms for
  // ceres::Covariance with SPARSE_QR, the same covariances). A batch over hundreds of keyframes is
  // not: its dense part would be too large, and ceres::Covariance takes it.
  constexpr int kMaxSchurDenseSize = 300;
  if (schurLandmarkCovariances(problem, landmarks, kMaxSchurDenseSize, &out)) {
    if (cross != nullptr)
      *cross = landmarkCrossCovariances(problem, landmarks, pairs);
    return out;
  }
  out.clear();
  std::vector<std::pair<int, int>> blocks;
  for (const auto& [id, block] : landmarks)
    blocks.emplace_back(id, id);
  if (cross != nullptr) {
    cross->clear();
    const std::vector<std::pair<int, int>> distinct = crossPairs(pairs);
    blocks.insert(blocks.end(), distinct.begin(), distinct.end());
  }
  for (const auto& [pair, c] : ceresCovarianceBlocks(problem, landmarks, blocks)) {
    if (pair.first != pair.second) {
      (*cross)[pair] = c;
      continue;
    }
    const Eigen::MatrixXd accepted = acceptedCovariance(c);
    if (accepted.size() > 0)
      out[pair.first] = accepted;
  }
  return out;
}

std::map<std::pair<int, int>, Eigen::MatrixXd> landmarkCrossCovariances(
    ceres::Problem* problem, const std::map<int, LandmarkBlock>& landmarks,
    const std::vector<std::pair<int, int>>& pairs) {
  return ceresCovarianceBlocks(problem, landmarks, crossPairs(pairs));
}

}  // namespace quadric_slam
