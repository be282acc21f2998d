#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "quadric_slam/eval/trajectory_metrics.h"
#include "../test_data.h"

using quadric_slam::AbsoluteTrajectoryError;
using quadric_slam::RelativePoseError;
using quadric_slam::StampedPose;
using quadric_slam::Trajectory;

namespace {

// A smooth hand-held-like motion sampled every `dt` seconds from t0.
Trajectory wavyTrajectory(double t0, double dt, int n) {
  Trajectory t;
  for (int k = 0; k < n; ++k) {
    const double s = t0 + dt * k, u = dt * k;
    StampedPose p;
    p.stamp = s;
    p.T_world_sensor.translation() =
        Eigen::Vector3d(std::sin(0.7 * u), 0.5 * std::cos(0.3 * u), 1.2 + 0.2 * std::sin(1.1 * u));
    p.T_world_sensor.linear() = (Eigen::AngleAxisd(0.4 * u, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(0.2 * std::sin(u), Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
    t.push_back(p);
  }
  return t;
}

}  // namespace

TEST(TrajectoryMetrics, AteIsZeroForARigidlyMovedCopyAndRecoversTheTransform) {
  const Trajectory gt = wavyTrajectory(100.0, 0.01, 600);
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  T_gt_est.linear() =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
  T_gt_est.translation() = Eigen::Vector3d(4, -1, 0.5);
  Trajectory est;
  for (std::size_t k = 0; k < gt.size(); k += 3) {  // 30 Hz estimate, stamps 4 ms late
    est.push_back({gt[k].stamp + 0.004, T_gt_est.inverse() * gt[k].T_world_sensor});
  }
  const auto ate = AbsoluteTrajectoryError().evaluate(gt, est);
  EXPECT_EQ(ate.pairs(), est.size());
  EXPECT_LT(ate.rmse(), 1e-9);
  EXPECT_TRUE(ate.T_gt_est.isApprox(T_gt_est, 1e-9));
  // Against 10 Hz ground truth, stamps 0.03 s off do not associate with the default 0.02 s gate.
  Trajectory sparse_gt, late_est;
  for (std::size_t k = 0; k < gt.size(); k += 10) {
    sparse_gt.push_back(gt[k]);
    late_est.push_back({gt[k].stamp + 0.03, gt[k].T_world_sensor});
  }
  EXPECT_THROW(AbsoluteTrajectoryError().evaluate(sparse_gt, late_est), std::runtime_error);
}

TEST(TrajectoryMetrics, AteOfATranslatedPointIsMeasuredAfterAlignment) {
  // Three points of an equilateral triangle; the estimate lifts one of them by e along the
  // triangle's normal. A translation-only fit leaves rmse e * sqrt(2) / 3; the rigid fit may also
  // tilt, so it does at least as well, and no small rotation (with its best translation) beats it.
  Trajectory gt, est;
  const double e = 0.3;
  for (int k = 0; k < 3; ++k) {
    const double a = 2.0 * M_PI * k / 3.0;
    StampedPose p;
    p.stamp = k;
    p.T_world_sensor.translation() = Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    gt.push_back(p);
    if (k == 0)
      p.T_world_sensor.translation().z() += e;
    est.push_back(p);
  }
  const auto ate = AbsoluteTrajectoryError().evaluate(gt, est);
  ASSERT_EQ(ate.pairs(), 3u);
  EXPECT_GT(ate.rmse(), 0.0);
  EXPECT_LE(ate.rmse(), e * std::sqrt(2.0) / 3.0 + 1e-12);
  std::mt19937 rng(3);
  std::normal_distribution<double> small(0.0, 1e-3);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(small(rng) + 1e-3,
                          Eigen::Vector3d(small(rng), small(rng), 1).normalized())
            .toRotationMatrix() *
        ate.T_gt_est.linear();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();  // best translation for this rotation
    for (int k = 0; k < 3; ++k) {
      t += gt[k].T_world_sensor.translation() - R * est[k].T_world_sensor.translation();
    }
    t /= 3.0;
    double sum = 0;
    for (int k = 0; k < 3; ++k) {
      sum += (R * est[k].T_world_sensor.translation() + t - gt[k].T_world_sensor.translation())
                 .squaredNorm();
    }
    EXPECT_GE(std::sqrt(sum / 3.0), ate.rmse() - 1e-12);
  }
}

TEST(TrajectoryMetrics, RpeOfAConstantVelocityDriftIsThatVelocity) {
  // Estimate = ground truth plus a world-frame drift d * t: every 1 s pair is off by |d| metres,
  // whatever the rotation, and the rotation error is zero.
  const Trajectory gt = wavyTrajectory(50.0, 0.01, 1000);
  const Eigen::Vector3d drift(0.03, -0.04, 0.0);  // |d| = 0.05 m/s
  Trajectory est;
  for (std::size_t k = 0; k < gt.size(); k += 5) {
    StampedPose p = gt[k];
    p.T_world_sensor.translation() += drift * (p.stamp - 50.0);
    est.push_back(p);
  }
  const auto rpe = RelativePoseError().evaluate(gt, est);
  // 200 estimate poses over 9.95 s: pairs (i, i + 20) for i < 179 (j = 199 is the last pose).
  EXPECT_EQ(rpe.pairs(), 179u);
  EXPECT_NEAR(rpe.translation.rmse, 0.05, 1e-9);
  EXPECT_NEAR(rpe.translation.max, 0.05, 1e-9);
  EXPECT_LT(rpe.rotation.rmse, 1e-6);
  // A 2 s delta doubles the drift per pair.
  RelativePoseError::Params params;
  params.delta = 2.0;
  EXPECT_NEAR(RelativePoseError(params).evaluate(gt, est).translation.rmse, 0.1, 1e-9);
  params.delta = -1.0;
  EXPECT_THROW(RelativePoseError{params}, std::invalid_argument);
}

TEST(TrajectoryMetrics, ReproducesTumEvaluateAteOnRealTrajectories) {
  const std::string dir = quadric_slam::test::sharedData("tum_groundtruth/").string();
  QS_SKIP_WITHOUT_SHARED_DATA(dir, quadric_slam::test::kFullGroundTruth);
  struct Reference {
    const char* sequence;
    std::size_t pairs;
    double rmse;
  };
  // ../shared/data/README.md: TUM evaluate_ate.py (groundtruth, rgbdslam), default options.
  const Reference references[] = {{"freiburg1_xyz", 786, 0.013473},
                                  {"freiburg1_desk", 574, 0.025831},
                                  {"freiburg2_desk", 2201, 0.095053},
                                  {"freiburg1_room", 1332, 0.101165},
                                  {"freiburg2_xyz", 3575, 0.026112}};
  for (const Reference& r : references) {
    const Trajectory gt =
        quadric_slam::readTumTrajectory(dir + "rgbd_dataset_" + r.sequence + "-groundtruth.txt");
    const Trajectory est = quadric_slam::readTumTrajectory(dir + r.sequence + "-rgbdslam.txt");
    const auto ate = AbsoluteTrajectoryError().evaluate(gt, est);
    EXPECT_EQ(ate.pairs(), r.pairs) << r.sequence;
    // The reference is printed with 6 decimals: 5e-7 rounding plus the 1e-5 requirement.
    EXPECT_NEAR(ate.rmse(), r.rmse, 1e-5) << r.sequence;
    EXPECT_NEAR(ate.rmse(), r.rmse, 5e-7 + 1e-12) << r.sequence << " (print rounding)";
    const auto rpe = RelativePoseError().evaluate(gt, est);
    EXPECT_GT(rpe.pairs(), 100u) << r.sequence;
    EXPECT_GT(rpe.translation.rmse, 0.0) << r.sequence;
    EXPECT_LT(rpe.translation.rmse, 0.5) << r.sequence;  // drift of a working SLAM system, m/s
  }
}

TEST(TrajectoryMetrics, RpeMatchesAPlainTranscriptionOfEvaluateRpe) {
  const std::string dir = quadric_slam::test::sharedData("tum_groundtruth/").string();
  QS_SKIP_WITHOUT_SHARED_DATA(dir, quadric_slam::test::kFullGroundTruth);
  // Values from a line-by-line pure-Python transcription of TUM's evaluate_rpe.py with
  // --fixed_delta --delta 1 --delta_unit s (pairs, translational_error.rmse printed with %f).
  struct Reference {
    const char* sequence;
    std::size_t pairs;
    double rmse;
  };
  const Reference references[] = {{"freiburg1_xyz", 753, 0.021217},
                                  {"freiburg1_desk", 542, 0.033252}};
  for (const Reference& r : references) {
    const Trajectory gt =
        quadric_slam::readTumTrajectory(dir + "rgbd_dataset_" + r.sequence + "-groundtruth.txt");
    const Trajectory est = quadric_slam::readTumTrajectory(dir + r.sequence + "-rgbdslam.txt");
    const auto rpe = RelativePoseError().evaluate(gt, est);
    EXPECT_EQ(rpe.pairs(), r.pairs) << r.sequence;
    EXPECT_NEAR(rpe.translation.rmse, r.rmse, 5e-7 + 1e-12) << r.sequence;
  }
}
