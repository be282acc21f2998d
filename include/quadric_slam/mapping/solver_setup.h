// What the sliding window (mapping/window.h) and the offline batch (mapping/batch_refiner.h) set up
// alike on Ceres: the solver options (Schur elimination of the landmarks, one thread, silent) and
// the landmarks' marginal covariances after a solve.
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <map>
#include <utility>
#include <vector>

namespace quadric_slam {

// Sparse Schur (the landmarks are eliminated first), one thread (the pipeline's other stages own
// the other cores), no output; the caller picks the trust-region strategy.
ceres::Solver::Options landmarkSolverOptions(int max_iterations);

// landmarkSolverOptions for a sliding window of `pose_blocks` keyframes: dense Schur while the
// reduced system (the poses and the landmarks a marginalisation prior ties together, a few hundred
// variables) is small enough that a dense Cholesky beats a sparse one's bookkeeping, sparse above.
ceres::Solver::Options windowSolverOptions(int max_iterations, int pose_blocks);

// One landmark's parameter block in a solved problem and the size of its minimal tangent.
struct LandmarkBlock {
  const double* parameters = nullptr;
  int minimal_size = 0;
};

// covariance symmetrised, or an empty matrix when it is not finite or not positive definite: the
// test every landmark covariance passes before the map keeps it.
Eigen::MatrixXd acceptedCovariance(const Eigen::MatrixXd& covariance);

// The marginal covariances of `landmarks` (id -> block) in their minimal tangent spaces, symmetric
// and positive definite; an id whose block Ceres cannot give (e.g. a gauge left free) is left out,
// and all are when the problem is rank-deficient. With `cross`, also the cross-covariances of
// `pairs` (as landmarkCrossCovariances below), from the same factorisation when ceres::Covariance
// computes the marginals: one sparse QR instead of two.
std::map<int, Eigen::MatrixXd> landmarkCovariances(
    ceres::Problem* problem, const std::map<int, LandmarkBlock>& landmarks,
    const std::vector<std::pair<int, int>>& pairs = {},
    std::map<std::pair<int, int>, Eigen::MatrixXd>* cross = nullptr);

// Cross-covariances Cov(a, b) (rows: a's minimal tangent, columns: b's) of the requested pairs of
// `landmarks` (ids), by ceres::Covariance (SPARSE_QR), keyed by the pair as given; a pair Ceres
// cannot give is left out, and all are when the problem is rank-deficient.
std::map<std::pair<int, int>, Eigen::MatrixXd> landmarkCrossCovariances(
    ceres::Problem* problem, const std::map<int, LandmarkBlock>& landmarks,
    const std::vector<std::pair<int, int>>& pairs);

}  // namespace quadric_slam
