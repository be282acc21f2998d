// General quadrics (an ellipsoid: class general, signature (+1, +1, +1, -1)) as landmarks. The
// front-end may report an ellipsoid's axes in any order (its semi-axes come longest first, and two
// close semi-axes swap from view to view), so every measurement here is re-expressed by a random
// relabelling of its axes (geometry/symmetry.h: the scales follow their axes): the observation
// factor's Jacobians match numeric differentiation with the 9-parameter manifold; one ellipsoid
// seen from many poses becomes exactly one landmark (promoted after 5 observations) whose semi-axes
// converge within 5 mm; two landmarks of one ellipsoid merge (chi-square in the 9-dim minimal
// space) into one no less certain than either, while another ellipsoid beside it, or one 3 cm
// larger at the same place, stays apart.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <memory>
#include <random>

#include "cost_jacobian_checks.h"
#include "quadric_slam/eval/map_metrics.h"
#include "quadric_slam/eval/trajectory_metrics.h"
#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/mapping/factors.h"
#include "quadric_slam/mapping/landmark_merger.h"
#include "quadric_slam/mapping/quadric_mapper.h"
#include "quadric_slam/mapping/surface_fusion.h"
#include "synthetic_world.h"

namespace quadric_slam {
namespace {

const Eigen::Vector4d kEllipsoid(1, 1, 1, -1);

test::TrueLandmark ellipsoid(const Eigen::Vector3d& centre, double yaw,
                             const Eigen::Vector3d& semi_axes) {
  const Eigen::Isometry3d T =
      makeIsometry(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix(), centre);
  return {QuadricModel(QuadricClass::kGeneral, T, semi_axes.cwiseInverse(), kEllipsoid),
          {-semi_axes, semi_axes}};
}

// A random relabelling of the axes (one of the 24 frames of an ellipsoid).
Eigen::Isometry3d randomRelabelling(std::mt19937& rng) {
  const std::vector<Eigen::Matrix3d> all = generalAxisRelabellings(kEllipsoid);
  const Eigen::Matrix3d& P =
      all[std::uniform_int_distribution<std::size_t>(0, all.size() - 1)(rng)];
  return makeIsometry(P, Eigen::Vector3d::Zero());
}

// test::measure with the ellipsoid's axes relabelled at random (covariance M C M^T).
QuadricMeasurement measureRelabelled(const test::TrueLandmark& l, const Eigen::Isometry3d& T_WC,
                                     std::mt19937& rng) {
  QuadricMeasurement m = test::measure(l, T_WC, rng);
  if (m.quadric_camera.quadricClass() != QuadricClass::kGeneral)
    return m;
  const Eigen::Isometry3d G = randomRelabelling(rng);
  const Eigen::MatrixXd M = minimalAdjoint(QuadricClass::kGeneral, G.inverse());
  const ExtentBox box =
      ExtentBox{m.extent_min, m.extent_max}.transformed(G.inverse());  // into the new frame
  m.quadric_camera = withSymmetry(m.quadric_camera, G);
  m.covariance = M * m.covariance * M.transpose();
  m.covariance = 0.5 * (m.covariance + m.covariance.transpose()).eval();
  m.extent_min = box.min;
  m.extent_max = box.max;
  return m;
}

TEST(GeneralLandmarks, ObservationJacobiansMatchNumericWithRelabelledMeasurements) {
  std::mt19937 rng(61);
  PoseManifold pose_manifold;
  QuadricManifold quadric_manifold(QuadricClass::kGeneral);
  const std::vector<const ceres::Manifold*> manifolds = {&pose_manifold, &quadric_manifold};
  for (int trial = 0; trial < 20; ++trial) {
    const test::TrueLandmark truth = ellipsoid(
        test::randomVector(rng, 1.0), test::uniform(rng, -3, 3), Eigen::Vector3d(0.3, 0.2, 0.12));
    const Eigen::Isometry3d T_WC = test::randomPose(rng);
    const QuadricMeasurement m = measureRelabelled(truth, T_WC, rng);
    std::unique_ptr<ceres::CostFunction> cost(
        QuadricObservationCost::Create(m.quadric_camera, m.covariance));
    // At a state away from the measurement (nonzero residual), and the alignment must have undone
    // the relabelling: the residual is small against the swap of two axes.
    Eigen::VectorXd d(9);
    for (int i = 0; i < 9; ++i)
      d[i] = test::uniform(rng, -0.02, 0.02);
    std::array<double, kPoseParameterSize> pose;
    std::array<double, kQuadricParameterSize> quadric;
    Vector6d xi;
    for (int i = 0; i < 6; ++i)
      xi[i] = test::uniform(rng, -0.01, 0.01);
    poseToParameters(plus(T_WC, xi), pose.data());
    quadricToParameters(truth.quadric_world.plusMinimal(d), quadric.data());
    const Eigen::VectorXd r = test::evaluate(*cost, {pose.data(), quadric.data()});
    ASSERT_TRUE(r.allFinite());
    EXPECT_LT(r.norm(), 40.0) << "trial " << trial << ": the relabelling was not undone";
    test::expectCostJacobians(*cost, {pose.data(), quadric.data()}, manifolds,
                              "trial " + std::to_string(trial) + " ");
  }
}

// The room of the mapper's tests with an ellipsoid (semi-axes 0.3, 0.2, 0.15 m) in it, one lap.
TEST(GeneralLandmarks, OneEllipsoidSeenFromManyPosesIsMappedOnce) {
  std::vector<test::TrueLandmark> world = test::roomWorld();
  const Eigen::Vector3d semi_axes(0.3, 0.2, 0.15);
  world.push_back(ellipsoid(Eigen::Vector3d(3.0, -0.3, 0.6), 0.7, semi_axes));
  const std::size_t truth_index = world.size() - 1;
  const std::vector<Eigen::Isometry3d> poses = test::circleTrajectory(300, 1.0);
  std::mt19937 rng(62);
  const std::vector<Eigen::Isometry3d> odometry = test::driftingOdometry(poses, rng);
  QuadricMapper mapper;
  Trajectory truth, estimate;
  int seen = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    FrameMeasurements frame;
    frame.stamp = 1.0 + i / 30.0;
    for (std::size_t l = 0; l < world.size(); ++l) {
      if (!test::visible(world[l], poses[i]))
        continue;
      frame.observations.push_back(measureRelabelled(world[l], poses[i], rng));
      seen += l == truth_index;
    }
    OdometryInput odom;
    odom.T_odom_camera = odometry[i];
    const MapperFrameResult r = mapper.process(frame, odom);
    ASSERT_EQ(r.status, FrameStatus::kOk) << r.message;
    truth.push_back({frame.stamp, poses[i]});
    estimate.push_back({frame.stamp, r.T_map_camera});
  }
  ASSERT_GE(seen, 30) << "the ellipsoid must be seen often for this test to mean anything";
  const std::vector<QuadricLandmark> landmarks = mapper.landmarks();
  std::vector<QuadricLandmark> general;
  std::copy_if(landmarks.begin(), landmarks.end(), std::back_inserter(general),
               [](const QuadricLandmark& l) {
                 return l.quadric_map.quadricClass() == QuadricClass::kGeneral;
               });
  ASSERT_EQ(general.size(), 1u) << "seen in " << seen << " frames";
  EXPECT_EQ(general[0].quadric_map.signature(), kEllipsoid);
  EXPECT_GE(general[0].observations, seen / 2);
  EXPECT_EQ(general[0].covariance.rows(), 9);

  // In the truth frame (the ATE alignment), through the map evaluator's ellipsoid errors.
  const AteResult ate = AbsoluteTrajectoryError().evaluate(truth, estimate);
  MapFile truth_map, estimate_map;
  MapFileQuadric t = test::toMapFile(1, world[truth_index].quadric_world, 0);
  MapFileQuadric e = test::toMapFile(general[0].id, general[0].quadric_map, 0);
  t.quadric_class = e.quadric_class = "ellipsoid";
  truth_map.quadrics = {t};
  estimate_map.quadrics = {e};
  const MapReport report = MapEvaluator().evaluate(truth_map, estimate_map, ate.T_gt_est);
  ASSERT_EQ(report.matched, 1);
  for (const ShapeError& error : report.truths[0].errors) {
    std::printf("%s %.4f\n", error.name.c_str(), error.value);
    if (error.name.rfind("semi_axis", 0) == 0) {
      EXPECT_LT(error.value, 0.005) << error.name;
    }
  }
  EXPECT_LT(report.truths[0].errors[0].value, 0.02);  // centre_m, with the trajectory's error
}

// A landmark with the whole ellipsoid's box as its extent.
QuadricLandmark landmarkOf(int id, const QuadricModel& q, const Eigen::MatrixXd& covariance,
                           int observations) {
  QuadricLandmark l;
  l.id = id;
  l.quadric_map = q;
  l.covariance = covariance;
  l.observations = observations;
  const Eigen::Vector3d axes = q.scale().cwiseInverse();
  l.extent_min = -axes;
  l.extent_max = axes;
  return l;
}

TEST(GeneralLandmarks, TwoLandmarksOfOneEllipsoidMergeAndOthersStayApart) {
  std::mt19937 rng(63);
  const LandmarkMerger merger;
  const Eigen::Vector3d semi_axes(0.13, 0.08, 0.07);
  for (int trial = 0; trial < 10; ++trial) {
    const test::TrueLandmark truth =
        ellipsoid(test::randomVector(rng, 2.0), test::uniform(rng, -3, 3), semi_axes);
    // Two estimates of it: 2 mm / 2 mrad / 1% apart, covariances of a few observations.
    Eigen::MatrixXd C = test::measurementCovariance(truth.quadric_world) / 4.0;
    Eigen::VectorXd d(9);
    for (int i = 0; i < 9; ++i)
      d[i] = 0.5 * std::sqrt(C(i, i)) * test::uniform(rng, -1, 1);
    const QuadricLandmark a = landmarkOf(1, truth.quadric_world, C, 12);
    const Eigen::Isometry3d G = randomRelabelling(rng);
    const Eigen::MatrixXd M = minimalAdjoint(QuadricClass::kGeneral, G.inverse());
    Eigen::MatrixXd C_b = M * (1.5 * C) * M.transpose();
    C_b = 0.5 * (C_b + C_b.transpose()).eval();
    const QuadricLandmark b =
        landmarkOf(2, withSymmetry(truth.quadric_world.plusMinimal(d), G), C_b, 7);
    const LandmarkMerger::Comparison same = merger.compare(a, b);
    EXPECT_TRUE(same.sameSurface()) << "trial " << trial << " d2 " << same.squared_distance;
    EXPECT_LT(same.squared_distance, merger.gate(QuadricClass::kGeneral));
    std::map<int, QuadricLandmark> map = {{1, a}, {2, b}};
    ASSERT_EQ(merger.findDuplicates(map).size(), 1u);
    // The merged landmark is no less certain than either part (Loewner order).
    const QuadricLandmark f = merger.fused(a, b);
    ASSERT_EQ(f.covariance.rows(), 9);
    const Eigen::MatrixXd C_b_aligned = alignCovariance(b.quadric_map, C_b, a.quadric_map).matrix;
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a.covariance - f.covariance)
                  .eigenvalues()
                  .minCoeff(),
              -1e-12);
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C_b_aligned - f.covariance)
                  .eigenvalues()
                  .minCoeff(),
              -1e-12);
    EXPECT_LT((f.quadric_map.scale().cwiseInverse() - semi_axes).cwiseAbs().maxCoeff(), 0.005);

    // The same cushion 0.5 m away: the parameters differ and the extents do not touch.
    const QuadricModel beside = truth.quadric_world.transformed(
        makeIsometry(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.5, 0, 0)));
    EXPECT_FALSE(merger.compare(a, landmarkOf(3, beside, C, 7)).sameSurface());
    // A larger ellipsoid (semi-axes +3 cm) at the same place: the extents touch, the parameters do
    // not agree.
    const Eigen::Vector3d larger = semi_axes + Eigen::Vector3d::Constant(0.03);
    const QuadricModel big(QuadricClass::kGeneral, truth.quadric_world.pose(),
                           larger.cwiseInverse(), kEllipsoid);
    const LandmarkMerger::Comparison other = merger.compare(a, landmarkOf(4, big, C, 7));
    EXPECT_TRUE(other.extents_touch);
    EXPECT_FALSE(other.within_gate) << "d2 " << other.squared_distance;
  }
}

}  // namespace
}  // namespace quadric_slam
