// The landmarks' marginal covariances by the Schur complement (mapping/schur_covariance.h) against
// ceres::Covariance on the same solved-problem structure as a window: poses on the SE(3)
// manifold, landmarks of several classes on their quadric manifolds, observations tying one pose
// to one landmark (some behind a Huber loss), odometry, a constant pose, a constant landmark, and a
// prior tying two landmarks and a pose (as a marginalisation prior does). Also: the dense-size
// limit and a rank-deficient problem make it decline (the caller falls back to ceres::Covariance).
// And the cross-covariances of pairs of landmarks (mapping/solver_setup.h) against a dense one.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include <memory>
#include <random>
#include <vector>

#include "../test_support.h"
#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/schur_covariance.h"
#include "quadric_slam/mapping/solver_setup.h"

namespace quadric_slam {
namespace {

// r = sum_i A_i x_i + b over blocks of the given ambient sizes (random A_i, b): a residual whose
// Jacobians are known, so both covariance methods see the same J^T J.
class RandomLinearCost : public ceres::CostFunction {
 public:
  RandomLinearCost(const std::vector<int>& block_sizes, int residuals, std::mt19937& rng) {
    std::normal_distribution<double> gauss(0.0, 1.0);
    set_num_residuals(residuals);
    for (int size : block_sizes) {
      mutable_parameter_block_sizes()->push_back(size);
      Eigen::MatrixXd A(residuals, size);
      for (int r = 0; r < residuals; ++r)
        for (int c = 0; c < size; ++c)
          A(r, c) = gauss(rng);
      A_.push_back(A);
    }
    b_ = Eigen::VectorXd(residuals);
    for (int r = 0; r < residuals; ++r)
      b_[r] = 0.3 * gauss(rng);
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    Eigen::Map<Eigen::VectorXd> r(residuals, num_residuals());
    r = b_;
    for (std::size_t i = 0; i < A_.size(); ++i) {
      r += A_[i] * Eigen::Map<const Eigen::VectorXd>(parameters[i], A_[i].cols());
      if (jacobians != nullptr && jacobians[i] != nullptr)
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[i], A_[i].rows(), A_[i].cols()) = A_[i];
    }
    return true;
  }

 private:
  std::vector<Eigen::MatrixXd> A_;
  Eigen::VectorXd b_;
};

ceres::Problem::Options notOwningManifolds() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

struct WindowLikeProblem {
  PoseManifold pose_manifold;
  std::vector<std::unique_ptr<QuadricManifold>> quadric_manifolds;
  ceres::Problem problem{notOwningManifolds()};  // after the manifolds: destroyed before them
  std::vector<std::array<double, kPoseParameterSize>> poses;
  std::vector<std::array<double, kQuadricParameterSize>> landmarks;
  std::map<int, LandmarkBlock> requested;  // the varying landmarks
};

// 5 poses (the first constant), 8 landmarks (plane, sphere, cylinder, cone, repeated; the last
// constant), each landmark seen from 3 poses; odometry between consecutive poses; a prior over
// landmarks 0 and 1 and pose 2. rank_deficient: landmark 2 is seen by one 1-row residual only.
// num_poses > 5: a longer odometry chain (a batch's size: too large a dense part for the Schur
// complement, so the covariances come from ceres::Covariance).
void build(WindowLikeProblem* w, bool rank_deficient, int num_poses = 5) {
  std::mt19937 rng(11);
  const QuadricClass classes[] = {QuadricClass::kPlane, QuadricClass::kSphere,
                                  QuadricClass::kCylinder, QuadricClass::kCone};
  w->poses.resize(num_poses);
  for (auto& pose : w->poses) {
    poseToParameters(test::randomPose(rng), pose.data());
    w->problem.AddParameterBlock(pose.data(), kPoseParameterSize, &w->pose_manifold);
  }
  w->problem.SetParameterBlockConstant(w->poses[0].data());
  w->landmarks.resize(8);
  for (int l = 0; l < 8; ++l) {
    const QuadricClass c = classes[l % 4];
    quadricToParameters(test::randomQuadric(c, rng), w->landmarks[l].data());
    w->quadric_manifolds.push_back(std::make_unique<QuadricManifold>(c));
    w->problem.AddParameterBlock(w->landmarks[l].data(), kQuadricParameterSize,
                                 w->quadric_manifolds.back().get());
    if (l == 7)
      w->problem.SetParameterBlockConstant(w->landmarks[l].data());
    else
      w->requested[l] = {w->landmarks[l].data(), w->quadric_manifolds.back()->TangentSize()};
  }
  for (int l = 0; l < 8; ++l) {
    const int seen_by = rank_deficient && l == 2 ? 1 : 3;
    for (int k = 0; k < seen_by; ++k) {
      const int p = (l + 2 * k) % 5;
      const int rows = rank_deficient && l == 2 ? 1 : 9;
      ceres::LossFunction* loss = (l + k) % 3 == 0 ? new ceres::HuberLoss(0.5) : nullptr;
      w->problem.AddResidualBlock(
          new RandomLinearCost({kPoseParameterSize, kQuadricParameterSize}, rows, rng), loss,
          w->poses[p].data(), w->landmarks[l].data());
    }
  }
  for (int p = 1; p < num_poses; ++p)
    w->problem.AddResidualBlock(
        new RandomLinearCost({kPoseParameterSize, kPoseParameterSize}, 6, rng), nullptr,
        w->poses[p - 1].data(), w->poses[p].data());
  w->problem.AddResidualBlock(
      new RandomLinearCost({kQuadricParameterSize, kQuadricParameterSize, kPoseParameterSize}, 20,
                           rng),
      nullptr, w->landmarks[0].data(), w->landmarks[1].data(), w->poses[2].data());
}

std::map<int, Eigen::MatrixXd> ceresCovariances(WindowLikeProblem* w) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (const auto& [id, block] : w->requested)
    pairs.emplace_back(block.parameters, block.parameters);
  std::map<int, Eigen::MatrixXd> out;
  if (!covariance.Compute(pairs, &w->problem))
    return out;
  for (const auto& [id, block] : w->requested) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> c(block.minimal_size,
                                                                             block.minimal_size);
    if (covariance.GetCovarianceBlockInTangentSpace(block.parameters, block.parameters, c.data()))
      out[id] = c;
  }
  return out;
}

TEST(SchurCovariance, AgreesWithCeresCovarianceOnAWindowLikeProblem) {
  WindowLikeProblem w;
  build(&w, false);
  const std::map<int, Eigen::MatrixXd> expected = ceresCovariances(&w);
  ASSERT_EQ(expected.size(), w.requested.size());
  std::map<int, Eigen::MatrixXd> schur;
  ASSERT_TRUE(schurLandmarkCovariances(&w.problem, w.requested, 300, &schur));
  ASSERT_EQ(schur.size(), w.requested.size());
  for (const auto& [id, c] : expected) {
    ASSERT_EQ(schur.at(id).rows(), c.rows()) << "landmark " << id;
    EXPECT_LE((schur.at(id) - c).norm(), 1e-8 * c.norm()) << "landmark " << id << "\n"
                                                          << schur.at(id) << "\n\n"
                                                          << c;
  }
  // The entry point the window and the batch call gives the same.
  const std::map<int, Eigen::MatrixXd> via_setup = landmarkCovariances(&w.problem, w.requested);
  ASSERT_EQ(via_setup.size(), w.requested.size());
  for (const auto& [id, c] : expected)
    EXPECT_LE((via_setup.at(id) - c).norm(), 1e-8 * c.norm()) << "landmark " << id;
}

TEST(SchurCovariance, DeclinesAboveTheDenseSizeAndOnARankDeficientProblem) {
  WindowLikeProblem w;
  build(&w, false);
  std::map<int, Eigen::MatrixXd> out;
  // Dense part: 4 varying poses (24) + the two landmarks of the prior.
  EXPECT_FALSE(schurLandmarkCovariances(&w.problem, w.requested, 24, &out));
  EXPECT_TRUE(out.empty());

  WindowLikeProblem deficient;
  build(&deficient, true);
  EXPECT_FALSE(schurLandmarkCovariances(&deficient.problem, deficient.requested, 300, &out));
  EXPECT_TRUE(out.empty());
  // Nor does the entry point report a covariance for the unobservable landmark.
  EXPECT_EQ(landmarkCovariances(&deficient.problem, deficient.requested).count(2), 0u);
}

// Cross-covariances of pairs of landmarks (the batch's merge test) against ceres::Covariance with
// a dense SVD on the same problem; a pair with a constant landmark or an unknown id is left out.
TEST(LandmarkCrossCovariances, AgreeWithADenseCovarianceOfThePair) {
  WindowLikeProblem w;
  build(&w, false);
  const std::vector<std::pair<int, int>> pairs = {{0, 1}, {1, 3}, {2, 5}, {6, 7}, {0, 42}};
  const std::map<std::pair<int, int>, Eigen::MatrixXd> cross =
      landmarkCrossCovariances(&w.problem, w.requested, pairs);
  EXPECT_EQ(cross.size(), 3u) << "landmark 7 is constant, 42 does not exist";
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance dense(options);
  std::vector<std::pair<const double*, const double*>> blocks;
  for (int i = 0; i < 3; ++i)
    blocks.emplace_back(w.requested.at(pairs[i].first).parameters,
                        w.requested.at(pairs[i].second).parameters);
  ASSERT_TRUE(dense.Compute(blocks, &w.problem));
  for (int i = 0; i < 3; ++i) {
    const LandmarkBlock& a = w.requested.at(pairs[i].first);
    const LandmarkBlock& b = w.requested.at(pairs[i].second);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> expected(a.minimal_size,
                                                                                    b.minimal_size);
    ASSERT_TRUE(
        dense.GetCovarianceBlockInTangentSpace(a.parameters, b.parameters, expected.data()));
    const Eigen::MatrixXd& got = cross.at(pairs[i]);
    ASSERT_EQ(got.rows(), a.minimal_size);
    ASSERT_EQ(got.cols(), b.minimal_size);
    EXPECT_GT(expected.norm(), 0.0);
    EXPECT_LE((got - Eigen::MatrixXd(expected)).norm(), 1e-8 * expected.norm())
        << pairs[i].first << "," << pairs[i].second;
  }
}

// The batch asks for the marginals and the cross-covariances of its near pairs at once: the same
// as asking for them apart, on the Schur path (a window's size) and on the ceres::Covariance one
// (a batch's, where both come from one factorisation).
TEST(LandmarkCrossCovariances, AskedWithTheMarginalsGiveTheSameAsApart) {
  for (const int num_poses : {5, 60}) {
    WindowLikeProblem w;
    build(&w, false, num_poses);
    std::map<int, Eigen::MatrixXd> out;
    EXPECT_EQ(schurLandmarkCovariances(&w.problem, w.requested, 300, &out), num_poses == 5);
    const std::vector<std::pair<int, int>> pairs = {{0, 1}, {1, 3}, {2, 5}, {6, 7}, {4, 4}};
    std::map<std::pair<int, int>, Eigen::MatrixXd> cross;
    const std::map<int, Eigen::MatrixXd> marginals =
        landmarkCovariances(&w.problem, w.requested, pairs, &cross);
    const std::map<int, Eigen::MatrixXd> marginals_apart =
        landmarkCovariances(&w.problem, w.requested);
    const std::map<std::pair<int, int>, Eigen::MatrixXd> cross_apart =
        landmarkCrossCovariances(&w.problem, w.requested, pairs);
    ASSERT_EQ(marginals.size(), w.requested.size()) << num_poses;
    ASSERT_EQ(marginals_apart.size(), marginals.size()) << num_poses;
    for (const auto& [id, c] : marginals_apart)
      EXPECT_LE((marginals.at(id) - c).norm(), 1e-8 * c.norm()) << num_poses << " " << id;
    EXPECT_EQ(cross.size(), 3u) << "landmark 7 is constant; (4, 4) is a marginal";
    ASSERT_EQ(cross_apart.size(), cross.size()) << num_poses;
    for (const auto& [pair, c] : cross_apart)
      EXPECT_LE((cross.at(pair) - c).norm(), 1e-8 * c.norm())
          << num_poses << " " << pair.first << "," << pair.second;
  }
}

}  // namespace
}  // namespace quadric_slam
