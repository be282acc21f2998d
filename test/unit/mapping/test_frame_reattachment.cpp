// The odometry chain between two refined keyframes (mapping/frame_reattachment.h): it reaches the
// later keyframe, leaves an odometry that already agrees untouched, puts the disagreement on the
// step whose covariance allows it, spreads it evenly over equally sure steps, and agrees with a
// dense weighted least-squares solve of the same chain.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "quadric_slam/geometry/se3.h"
#include "quadric_slam/mapping/frame_reattachment.h"

namespace quadric_slam {
namespace {

Vector6d twist(double tx, double ty, double tz, double rx, double ry, double rz) {
  Vector6d xi;
  xi << tx, ty, tz, rx, ry, rz;
  return xi;
}

std::vector<Eigen::Isometry3d> compose(const Eigen::Isometry3d& start,
                                       const std::vector<Eigen::Isometry3d>& steps) {
  std::vector<Eigen::Isometry3d> out;
  Eigen::Isometry3d X = start;
  for (const Eigen::Isometry3d& step : steps)
    out.push_back(X = X * step);
  return out;
}

// A camera moving forward and turning a little per frame.
std::vector<Eigen::Isometry3d> turningSteps(int n) {
  std::vector<Eigen::Isometry3d> steps;
  for (int i = 0; i < n; ++i)
    steps.push_back(expSE3(twist(0.01, 0.002 * i, 0.004, 0.003, -0.01, 0.005 * (i % 3))));
  return steps;
}

TEST(SmoothOdometryChain, AnOdometryThatReachesTheEndIsLeftAlone) {
  const Eigen::Isometry3d start = expSE3(twist(0.3, -0.2, 1.0, 0.1, 0.2, -0.3));
  const std::vector<Eigen::Isometry3d> steps = turningSteps(8);
  const std::vector<Eigen::Isometry3d> odometry = compose(start, steps);
  const std::vector<Eigen::Isometry3d> chain = smoothOdometryChain(
      start, steps, std::vector<Matrix6d>(steps.size(), 1e-6 * Matrix6d::Identity()),
      odometry.back());
  ASSERT_EQ(chain.size(), steps.size());
  for (std::size_t k = 0; k < chain.size(); ++k)
    EXPECT_LT(minus(chain[k], odometry[k]).norm(), 1e-12) << k;
}

TEST(SmoothOdometryChain, ReachesTheEndPose) {
  const Eigen::Isometry3d start = expSE3(twist(0.3, -0.2, 1.0, 0.1, 0.2, -0.3));
  const std::vector<Eigen::Isometry3d> steps = turningSteps(10);
  // The refined end 4 cm and 3 degrees away from where the odometry puts it.
  const Eigen::Isometry3d end =
      compose(start, steps).back() * expSE3(twist(0.03, -0.02, 0.015, 0.03, -0.03, 0.02));
  std::vector<Matrix6d> covariances;
  for (int k = 0; k < 10; ++k)
    covariances.push_back((1e-6 * (1 + k % 4)) * Matrix6d::Identity());
  const std::vector<Eigen::Isometry3d> chain = smoothOdometryChain(start, steps, covariances, end);
  EXPECT_LT(minus(chain.back(), end).norm(), 1e-9);
}

// A degenerate frame (ICP could not see the slide along a wall, x here) took a 5 cm wrong step; the
// other steps are right. Its covariance says so, and the chain puts the whole correction there.
TEST(SmoothOdometryChain, TheCorrectionLandsOnTheStepThatCouldNotMeasureIt) {
  const Eigen::Isometry3d start = expSE3(twist(0.1, 0.2, -0.1, 0.05, -0.1, 0.2));
  const std::vector<Eigen::Isometry3d> truth_steps = turningSteps(9);
  const std::vector<Eigen::Isometry3d> truth = compose(start, truth_steps);
  const int degenerate = 4;
  std::vector<Eigen::Isometry3d> odometry_steps = truth_steps;
  odometry_steps[degenerate] = odometry_steps[degenerate] * expSE3(twist(0.05, 0, 0, 0, 0, 0));
  std::vector<Matrix6d> covariances(truth_steps.size(), 1e-6 * Matrix6d::Identity());
  covariances[degenerate](0, 0) = 1.0;  // 1 m^2 along x: the tracker's report for a weak direction

  const std::vector<Eigen::Isometry3d> chain =
      smoothOdometryChain(start, odometry_steps, covariances, truth.back());
  for (std::size_t k = 0; k < chain.size(); ++k)
    EXPECT_LT(minus(chain[k], truth[k]).norm(), 1e-5) << k;
  // Hung from the start instead, every frame from the degenerate one on is 5 cm off.
  const std::vector<Eigen::Isometry3d> hung = compose(start, odometry_steps);
  EXPECT_GT((hung[degenerate].translation() - truth[degenerate].translation()).norm(), 0.049);
}

// Equally sure steps along a straight line share a translation disagreement equally: frame k of n
// moves k/n of it.
TEST(SmoothOdometryChain, EquallySureStepsShareTheCorrectionEvenly) {
  const int n = 6;
  const std::vector<Eigen::Isometry3d> steps(n, expSE3(twist(0, 0, 0.02, 0, 0, 0)));
  const Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d gap(0.012, -0.006, 0.003);
  Eigen::Isometry3d end = compose(start, steps).back();
  end.translation() += gap;
  // The rotations well known (otherwise tilting the early steps moves the later frames too).
  Matrix6d covariance = Matrix6d::Zero();
  covariance.diagonal() << 1e-6, 1e-6, 1e-6, 1e-14, 1e-14, 1e-14;
  const std::vector<Eigen::Isometry3d> chain =
      smoothOdometryChain(start, steps, std::vector<Matrix6d>(n, covariance), end);
  const std::vector<Eigen::Isometry3d> odometry = compose(start, steps);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d moved = chain[k].translation() - odometry[k].translation();
    EXPECT_LT((moved - gap * (k + 1.0) / n).norm(), 1e-8) << k;
    EXPECT_LT(Eigen::AngleAxisd(chain[k].rotation()).angle(), 1e-8) << k;
  }
}

// Against a dense solve of the same problem: the corrections xi minimise sum xi_i^T Sigma_i^-1 xi_i
// among those that reach the end, so any other correction that reaches it (the solution plus a
// step in the constraint's null space, projected back onto the end) costs more.
TEST(SmoothOdometryChain, IsTheLeastCostCorrectionThatReachesTheEnd) {
  std::mt19937 rng(7);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Isometry3d start = expSE3(twist(0.5, 0.1, 0.2, -0.2, 0.1, 0.3));
  const std::vector<Eigen::Isometry3d> steps = turningSteps(7);
  std::vector<Matrix6d> covariances;
  for (int k = 0; k < 7; ++k) {
    Eigen::Matrix<double, 6, 6> A;
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c)
        A(r, c) = 0.003 * gauss(rng);
    covariances.push_back(A * A.transpose() + 1e-7 * Matrix6d::Identity());
  }
  const Eigen::Isometry3d end =
      compose(start, steps).back() * expSE3(twist(0.01, 0.02, -0.01, 0.01, 0.0, -0.01));
  const std::vector<Eigen::Isometry3d> chain = smoothOdometryChain(start, steps, covariances, end);

  auto corrections = [&](const std::vector<Eigen::Isometry3d>& poses) {
    std::vector<Vector6d> xi;
    Eigen::Isometry3d previous = start;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      xi.push_back(logSE3(steps[k].inverse() * previous.inverse() * poses[k]));
      previous = poses[k];
    }
    return xi;
  };
  auto cost = [&](const std::vector<Vector6d>& xi) {
    double c = 0.0;
    for (std::size_t k = 0; k < xi.size(); ++k)
      c += xi[k].dot(covariances[k].ldlt().solve(xi[k]));
    return c;
  };
  const std::vector<Vector6d> best = corrections(chain);
  const double best_cost = cost(best);
  for (int trial = 0; trial < 20; ++trial) {
    // Perturb two steps' corrections against each other, then let the last step close the chain.
    std::vector<Vector6d> xi = best;
    Vector6d d;
    for (int r = 0; r < 6; ++r)
      d(r) = 1e-3 * gauss(rng);
    xi[trial % 5] += d;
    xi[5] -= d;
    std::vector<Eigen::Isometry3d> perturbed;
    Eigen::Isometry3d X = start;
    for (int k = 0; k < 6; ++k)
      perturbed.push_back(X = X * steps[k] * expSE3(xi[k]));
    perturbed.push_back(end);
    EXPECT_GT(cost(corrections(perturbed)), best_cost) << trial;
  }
}

TEST(SmoothOdometryChain, MismatchedSizesThrowAndAnEmptyChainIsEmpty) {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_THROW(smoothOdometryChain(I, turningSteps(3), std::vector<Matrix6d>(2), I),
               std::invalid_argument);
  EXPECT_TRUE(smoothOdometryChain(I, {}, {}, I).empty());
}

// Steps that carry no covariance cannot say where the correction belongs: the chain is the
// odometry hung from its start.
TEST(SmoothOdometryChain, WithoutCovariancesTheChainHangsFromItsStart) {
  const Eigen::Isometry3d start = expSE3(twist(0.1, 0, 0, 0, 0, 0.1));
  const std::vector<Eigen::Isometry3d> steps = turningSteps(4);
  const Eigen::Isometry3d end = compose(start, steps).back() * expSE3(twist(0.02, 0, 0, 0, 0, 0));
  const std::vector<Eigen::Isometry3d> chain =
      smoothOdometryChain(start, steps, std::vector<Matrix6d>(4, Matrix6d::Zero()), end);
  const std::vector<Eigen::Isometry3d> odometry = compose(start, steps);
  for (std::size_t k = 0; k < chain.size(); ++k)
    EXPECT_LT(minus(chain[k], odometry[k]).norm(), 1e-12) << k;
}

}  // namespace
}  // namespace quadric_slam
