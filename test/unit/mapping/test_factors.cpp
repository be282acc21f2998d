#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <array>
#include <iostream>
#include <memory>
#include <random>

#include "../test_support.h"
#include "cost_jacobian_checks.h"
#include "quadric_slam/geometry/manifolds.h"
#include "quadric_slam/geometry/surface_distance.h"
#include "quadric_slam/geometry/symmetry.h"
#include "quadric_slam/mapping/factors.h"

namespace quadric_slam {
namespace {

using PoseBlock = std::array<double, kPoseParameterSize>;
using QuadricBlock = std::array<double, kQuadricParameterSize>;

Eigen::VectorXd randomVectorX(std::mt19937& rng, int n, double sigma) {
  std::normal_distribution<double> gauss(0.0, sigma);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i)
    v[i] = gauss(rng);
  return v;
}

// A noisy observation of `truth` from T_WC: h(T_WC, pi) [+] nu (eq. 18), nu ~ N(0, sigma^2 I) in
// the class's minimal space, re-expressed in a random frame of the same surface (its symmetry
// orbit) so that the cost must not depend on the frame the front-end happened to choose. The
// covariance in that frame is returned in *covariance (M sigma^2 M^T, M = minimalAdjoint(G^-1)).
QuadricModel observe(const QuadricModel& truth, const Eigen::Isometry3d& T_WC, double sigma,
                     std::mt19937& rng, Eigen::MatrixXd* covariance = nullptr) {
  const QuadricClass c = truth.quadricClass();
  const int k = minimalDimension(c);
  const QuadricModel h = predictMeasurement(T_WC, truth);
  const QuadricModel noisy = h.plusMinimal(randomVectorX(rng, k, sigma));
  const Eigen::Isometry3d G = test::randomSymmetry(c, rng);
  if (covariance != nullptr) {
    const Eigen::MatrixXd M = minimalAdjoint(c, G.inverse());
    *covariance = sigma * sigma * M * M.transpose();
    *covariance = 0.5 * (*covariance + covariance->transpose()).eval();
  }
  return QuadricModel(c, noisy.pose() * G, noisy.scale(), noisy.signature());
}

void expectObservationJacobians(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  PoseManifold pose_manifold;
  QuadricManifold quadric_manifold(c);
  for (int trial = 0; trial < 10; ++trial) {
    const QuadricModel truth = test::randomQuadric(c, rng);
    const Eigen::Isometry3d T_WC = test::randomPose(rng);
    const QuadricModel z = observe(truth, T_WC, 0.05, rng);
    const int k = minimalDimension(c);
    Eigen::MatrixXd cov = Eigen::MatrixXd::Random(k, k);
    cov = cov * cov.transpose() * 0.01 + 0.01 * Eigen::MatrixXd::Identity(k, k);
    std::unique_ptr<ceres::CostFunction> cost(QuadricObservationCost::Create(z, cov));
    // Evaluate at a state away from the measurement (nonzero residual).
    const QuadricModel state = truth.plusMinimal(randomVectorX(rng, k, 0.2));
    PoseBlock pose;
    QuadricBlock quadric;
    poseToParameters(plus(T_WC, randomVectorX(rng, 6, 0.1)), pose.data());
    quadricToParameters(state, quadric.data());
    test::expectCostJacobians(*cost, {pose.data(), quadric.data()},
                              {&pose_manifold, &quadric_manifold});
  }
}

TEST(PlaneFactor, JacobianMatchesNumeric) {
  expectObservationJacobians(QuadricClass::kPlane, 41);
}
TEST(SphereFactor, JacobianMatchesNumeric) {
  expectObservationJacobians(QuadricClass::kSphere, 42);
}
TEST(CylinderFactor, JacobianMatchesNumeric) {
  expectObservationJacobians(QuadricClass::kCylinder, 43);
}
TEST(ConeFactor, JacobianMatchesNumeric) {
  expectObservationJacobians(QuadricClass::kCone, 44);
}
TEST(GeneralFactor, JacobianMatchesNumeric) {
  expectObservationJacobians(QuadricClass::kGeneral, 45);
}

TEST(RelativePoseFactor, JacobianMatchesNumeric) {
  std::mt19937 rng(46);
  PoseManifold m;
  for (int trial = 0; trial < 10; ++trial) {
    Matrix6d cov = Matrix6d::Random();
    cov = cov * cov.transpose() * 0.01 + 0.01 * Matrix6d::Identity();
    std::unique_ptr<ceres::CostFunction> cost(RelativePoseCost::Create(test::randomPose(rng), cov));
    PoseBlock a, b;
    poseToParameters(test::randomPose(rng), a.data());
    poseToParameters(test::randomPose(rng), b.data());
    test::expectCostJacobians(*cost, {a.data(), b.data()}, {&m, &m});
  }
}

TEST(PosePriorFactor, JacobianMatchesNumeric) {
  std::mt19937 rng(47);
  PoseManifold m;
  for (int trial = 0; trial < 10; ++trial) {
    std::unique_ptr<ceres::CostFunction> cost(
        PosePriorCost::Create(test::randomPose(rng), 0.01 * Matrix6d::Identity()));
    PoseBlock a;
    poseToParameters(test::randomPose(rng), a.data());
    test::expectCostJacobians(*cost, {a.data()}, {&m});
  }
}

TEST(PosePriorFactor, ZeroAtPriorAndWhitened) {
  std::mt19937 rng(48);
  const Eigen::Isometry3d T = test::randomPose(rng);
  std::unique_ptr<ceres::CostFunction> cost(PosePriorCost::Create(T, 0.04 * Matrix6d::Identity()));
  PoseBlock a;
  poseToParameters(T, a.data());
  EXPECT_LT(test::evaluate(*cost, {a.data()}).norm(), 1e-12);
  Vector6d d = Vector6d::Zero();
  d[0] = 0.1;  // 0.1 m with sigma 0.2 m: whitened residual 0.5
  poseToParameters(plus(T, d), a.data());
  EXPECT_NEAR(test::evaluate(*cost, {a.data()})[0], 0.5, 1e-12);
}

TEST(QuadricObservationCost, RejectsBadCovariance) {
  const QuadricModel sphere;
  EXPECT_THROW(QuadricObservationCost::Create(sphere, Eigen::MatrixXd::Identity(3, 3)),
               std::invalid_argument);
  EXPECT_THROW(QuadricObservationCost::Create(sphere, -Eigen::MatrixXd::Identity(4, 4)),
               std::invalid_argument);
  delete QuadricObservationCost::Create(sphere, Eigen::MatrixXd::Identity(4, 4));
}

// The residual of one observation does not change when the measurement is re-expressed by any
// member of its symmetry orbit (with its covariance re-expressed accordingly, so an anisotropic
// covariance is the same physical uncertainty), and is zero when measurement and prediction are
// the same surface.
void expectResidualInvariant(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  const int k = minimalDimension(c);
  for (int trial = 0; trial < 20; ++trial) {
    const QuadricModel truth = test::randomQuadric(c, rng);
    const Eigen::Isometry3d T_WC = test::randomPose(rng);
    PoseBlock pose;
    QuadricBlock quadric;
    poseToParameters(T_WC, pose.data());
    quadricToParameters(truth, quadric.data());
    Eigen::MatrixXd cov = Eigen::MatrixXd::Random(k, k);
    cov = cov * cov.transpose() * 0.01 + 0.001 * Eigen::MatrixXd::Identity(k, k);
    const QuadricModel h = predictMeasurement(T_WC, truth);
    const QuadricModel h_other(c, h.pose() * test::randomSymmetry(c, rng), h.scale(),
                               h.signature());
    std::unique_ptr<ceres::CostFunction> exact(QuadricObservationCost::Create(h_other, cov));
    EXPECT_LT(test::evaluate(*exact, {pose.data(), quadric.data()}).norm(), 1e-9)
        << toString(c) << " trial " << trial;
    const QuadricModel z = h.plusMinimal(randomVectorX(rng, k, 0.1));
    const Eigen::Isometry3d G0 = test::randomSymmetry(c, rng);
    const QuadricModel z_other(c, z.pose() * G0, z.scale(), z.signature());
    const Eigen::MatrixXd M = minimalAdjoint(c, G0.inverse());
    const Eigen::MatrixXd cov_other = M * cov * M.transpose();
    std::unique_ptr<ceres::CostFunction> cost_a(QuadricObservationCost::Create(z, cov));
    std::unique_ptr<ceres::CostFunction> cost_b(
        QuadricObservationCost::Create(z_other, 0.5 * (cov_other + cov_other.transpose())));
    const Eigen::VectorXd ra = test::evaluate(*cost_a, {pose.data(), quadric.data()});
    const Eigen::VectorXd rb = test::evaluate(*cost_b, {pose.data(), quadric.data()});
    EXPECT_GT(ra.norm(), 1e-2);
    // The whitened residual vectors may differ by an orthogonal map (L is a square root of the
    // information); the cost and its Mahalanobis norm must not.
    EXPECT_NEAR(ra.squaredNorm(), rb.squaredNorm(), 1e-9 * (1 + ra.squaredNorm()))
        << toString(c) << " trial " << trial;
  }
}

TEST(SphereResidual, InvariantToRotation) {
  expectResidualInvariant(QuadricClass::kSphere, 51);
}
TEST(CylinderResidual, InvariantToAxisRotationSlideAndFlip) {
  expectResidualInvariant(QuadricClass::kCylinder, 52);
}
TEST(ConeResidual, InvariantToAxisRotationAndFlip) {
  expectResidualInvariant(QuadricClass::kCone, 53);
}
TEST(PlaneResidual, InvariantToInPlaneMotionAndFlip) {
  expectResidualInvariant(QuadricClass::kPlane, 54);
}
TEST(GeneralResidual, InvariantToAxisFlips) {
  expectResidualInvariant(QuadricClass::kGeneral, 55);
}

// Dense J^T J of the problem at its current state, in the tangent spaces of the manifolds.
Eigen::MatrixXd informationMatrix(ceres::Problem* problem, double* block) {
  ceres::CRSMatrix crs;
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks = {block};
  problem->Evaluate(options, nullptr, nullptr, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int r = 0; r < crs.num_rows; ++r) {
    for (int i = crs.rows[r]; i < crs.rows[r + 1]; ++i)
      J(r, crs.cols[i]) = crs.values[i];
  }
  return J.transpose() * J;
}

int numericalRank(const Eigen::MatrixXd& information) {
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(information);
  const double max_ev = eig.eigenvalues().cwiseAbs().maxCoeff();
  int rank = 0;
  for (int i = 0; i < eig.eigenvalues().size(); ++i)
    rank += eig.eigenvalues()[i] > 1e-9 * max_ev;
  return rank;
}

// Several noisy observations of one quadric from known camera poses: the estimate converges to
// the truth within the noise and the information matrix is full rank in the minimal space.
void expectSmallProblemConverges(QuadricClass c, int seed) {
  std::mt19937 rng(seed);
  const double sigma = 0.01;
  const int k = minimalDimension(c), n_obs = 12;
  const QuadricModel truth = test::randomQuadric(c, rng);
  std::vector<PoseBlock> poses(n_obs);
  QuadricBlock quadric;
  quadricToParameters(truth.plusMinimal(randomVectorX(rng, k, 0.15)), quadric.data());
  ceres::Problem problem;
  problem.AddParameterBlock(quadric.data(), kQuadricParameterSize, new QuadricManifold(c));
  for (int i = 0; i < n_obs; ++i) {
    const Eigen::Isometry3d T_WC = test::randomPose(rng, 3.0);
    poseToParameters(T_WC, poses[i].data());
    problem.AddParameterBlock(poses[i].data(), kPoseParameterSize, new PoseManifold);
    problem.SetParameterBlockConstant(poses[i].data());
    Eigen::MatrixXd cov;
    const QuadricModel z = observe(truth, T_WC, sigma, rng, &cov);
    problem.AddResidualBlock(QuadricObservationCost::Create(z, cov), nullptr, poses[i].data(),
                             quadric.data());
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  const QuadricModel estimate = quadricFromParameters(quadric.data(), c, truth.signature());
  const Eigen::VectorXd error = surfaceMinus(estimate, truth);
  // Each component averages n_obs draws of N(0, sigma^2) (in rotated local frames): 5 sigma /
  // sqrt(n).
  EXPECT_LT(error.cwiseAbs().maxCoeff(), 5.0 * sigma / std::sqrt(n_obs))
      << toString(c) << " error " << error.transpose();
  // chi^2 of n_obs * k residuals with k parameters: mean n_obs*k - k; 2*cost well inside [0.3, 2]x.
  const double dof = n_obs * k - k;
  EXPECT_GT(2 * summary.final_cost, 0.3 * dof);
  EXPECT_LT(2 * summary.final_cost, 2.0 * dof);
  const Eigen::MatrixXd info = informationMatrix(&problem, quadric.data());
  EXPECT_EQ(info.rows(), k);  // the quadric block in its tangent space
  EXPECT_EQ(numericalRank(info), k) << toString(c);
  std::cout << toString(c) << ": " << summary.iterations.size() - 1 << " iterations, final cost "
            << summary.final_cost << ", max |error| " << error.cwiseAbs().maxCoeff() << "\n";
}

TEST(PlaneFactor, SmallProblemConvergesWithFullRankInformation) {
  expectSmallProblemConverges(QuadricClass::kPlane, 61);
}
TEST(SphereFactor, SmallProblemConvergesWithFullRankInformation) {
  expectSmallProblemConverges(QuadricClass::kSphere, 62);
}
TEST(CylinderFactor, SmallProblemConvergesWithFullRankInformation) {
  expectSmallProblemConverges(QuadricClass::kCylinder, 63);
}
TEST(ConeFactor, SmallProblemConvergesWithFullRankInformation) {
  expectSmallProblemConverges(QuadricClass::kCone, 64);
}
TEST(GeneralFactor, SmallProblemConvergesWithFullRankInformation) {
  expectSmallProblemConverges(QuadricClass::kGeneral, 65);
}

// Algebraic distance of a fixed point to the quadric in the block (general signature (1,1,1,-1)).
struct PointOnEllipsoidResidual {
  explicit PointOnEllipsoidResidual(const Eigen::Vector3d& p) : p_(p) {}
  bool operator()(const double* q, double* residual) const {
    const QuadricModel quadric(QuadricClass::kGeneral, poseFromParameters(q),
                               Eigen::Vector3d(q[7], q[8], q[9]), Eigen::Vector4d(1, 1, 1, -1));
    residual[0] = algebraicDistance(quadric, p_);
    return true;
  }
  Eigen::Vector3d p_;
};

TEST(SphereInformation, GeneralFormIsRankDeficientMinimalFormIsNot) {
  // The paper's point (Section III-E): points on a sphere constrain its centre and radius, not a
  // rotation. In the general 9-parameter form J^T J is rank deficient (rank 6: position + three
  // scales); in the sphere's 4-parameter form (rho, alpha) it is full rank.
  std::mt19937 rng(66);
  const QuadricModel sphere = test::randomQuadric(QuadricClass::kSphere, rng);
  const double r = 1.0 / sphere.scale().x();
  for (QuadricClass form : {QuadricClass::kGeneral, QuadricClass::kSphere}) {
    QuadricBlock block;
    quadricToParameters(sphere, block.data());
    ceres::Problem problem;
    problem.AddParameterBlock(block.data(), kQuadricParameterSize, new QuadricManifold(form));
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector3d dir = test::randomVector(rng, 1.0).normalized();
      problem.AddResidualBlock(
          new ceres::NumericDiffCostFunction<PointOnEllipsoidResidual, ceres::CENTRAL, 1, 10>(
              new PointOnEllipsoidResidual(sphere.pose() * (r * dir))),
          nullptr, block.data());
    }
    const Eigen::MatrixXd info = informationMatrix(&problem, block.data());
    if (form == QuadricClass::kGeneral) {
      EXPECT_EQ(info.rows(), 9);
      EXPECT_EQ(numericalRank(info), 6);
    } else {
      EXPECT_EQ(info.rows(), 4);
      EXPECT_EQ(numericalRank(info), 4);
    }
  }
}

TEST(JointProblem, TenPosesFourQuadricsConvergeWithDogleg) {
  std::mt19937 rng(70);
  const int n_poses = 10;
  // Truth: a camera moving along x, looking roughly along +y, and four landmarks.
  std::vector<Eigen::Isometry3d> truth_poses;
  for (int i = 0; i < n_poses; ++i) {
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    truth_poses.push_back(makeIsometry(R, Eigen::Vector3d(0.3 * i, 0.02 * i * i, 1.2)));
  }
  const std::vector<QuadricModel> truth_quadrics = {
      QuadricModel(QuadricClass::kPlane, makeIsometry(Eigen::Matrix3d::Identity(), {0, 4, 0}),
                   Eigen::Vector3d::Ones()),  // wall x = 0 ... rotated below
      QuadricModel(QuadricClass::kSphere,
                   makeIsometry(Eigen::Matrix3d::Identity(), {1.0, 3.0, 0.8}),
                   Eigen::Vector3d::Constant(1 / 0.3)),
      QuadricModel(QuadricClass::kCylinder,
                   makeIsometry(Eigen::Matrix3d::Identity(), {2.0, 3.5, 0.0}),
                   Eigen::Vector3d(1 / 0.2, 1 / 0.2, 1)),
      QuadricModel(
          QuadricClass::kCone,
          makeIsometry(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix(),
                       {3.0, 3.0, 1.5}),
          Eigen::Vector3d(1 / std::tan(0.4), 1 / std::tan(0.4), 1))};
  std::vector<QuadricModel> quadrics = truth_quadrics;
  // The plane: y = 4 (normal = world y).
  quadrics[0] = QuadricModel(
      QuadricClass::kPlane,
      makeIsometry(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                   {0, 4, 0}),
      Eigen::Vector3d::Ones());
  const std::vector<QuadricModel> truth = {quadrics[0], truth_quadrics[1], truth_quadrics[2],
                                           truth_quadrics[3]};

  const double sigma_odom_t = 0.01, sigma_odom_r = 0.005, sigma_obs = 0.01;
  Matrix6d odom_cov = Matrix6d::Zero();
  odom_cov.diagonal() << Eigen::Vector3d::Constant(sigma_odom_t * sigma_odom_t),
      Eigen::Vector3d::Constant(sigma_odom_r * sigma_odom_r);

  ceres::Problem problem;
  std::vector<PoseBlock> poses(n_poses);
  std::vector<QuadricBlock> landmarks(truth.size());
  // Initial poses: dead reckoning from noisy odometry, then perturbed further.
  Eigen::Isometry3d chained = truth_poses[0];
  std::vector<Eigen::Isometry3d> odometry;
  for (int i = 0; i < n_poses; ++i) {
    if (i > 0) {
      const Eigen::Isometry3d T_ij = truth_poses[i - 1].inverse() * truth_poses[i];
      Vector6d noise;
      noise << randomVectorX(rng, 3, sigma_odom_t), randomVectorX(rng, 3, sigma_odom_r);
      const Eigen::Isometry3d measured = plus(T_ij, noise);
      chained = chained * measured;
      odometry.push_back(measured);
    }
    poseToParameters(plus(chained, randomVectorX(rng, 6, 0.1)), poses[i].data());
    problem.AddParameterBlock(poses[i].data(), kPoseParameterSize, new PoseManifold);
    if (i > 0)
      problem.AddResidualBlock(RelativePoseCost::Create(odometry.back(), odom_cov), nullptr,
                               poses[i - 1].data(), poses[i].data());
  }
  problem.AddResidualBlock(PosePriorCost::Create(truth_poses[0], 1e-6 * Matrix6d::Identity()),
                           nullptr, poses[0].data());
  for (size_t j = 0; j < truth.size(); ++j) {
    const QuadricClass c = truth[j].quadricClass();
    const int k = minimalDimension(c);
    quadricToParameters(truth[j].plusMinimal(randomVectorX(rng, k, 0.2)), landmarks[j].data());
    problem.AddParameterBlock(landmarks[j].data(), kQuadricParameterSize, new QuadricManifold(c));
    for (int i = 0; i < n_poses; ++i) {
      Eigen::MatrixXd cov;
      const QuadricModel z = observe(truth[j], truth_poses[i], sigma_obs, rng, &cov);
      problem.AddResidualBlock(QuadricObservationCost::Create(z, cov), nullptr, poses[i].data(),
                               landmarks[j].data());
    }
  }

  auto errors = [&](double* max_t, double* max_r, double* max_q) {
    *max_t = *max_r = *max_q = 0;
    for (int i = 0; i < n_poses; ++i) {
      const Vector6d e = minus(poseFromParameters(poses[i].data()), truth_poses[i]);
      *max_t = std::max(*max_t, poseFromParameters(poses[i].data())
                                    .translation()
                                    .
                                    operator-(truth_poses[i].translation())
                                    .norm());
      *max_r = std::max(*max_r, e.tail<3>().norm());
    }
    for (size_t j = 0; j < truth.size(); ++j) {
      const QuadricModel est =
          quadricFromParameters(landmarks[j].data(), truth[j].quadricClass(), truth[j].signature());
      *max_q = std::max(*max_q, surfaceMinus(est, truth[j]).cwiseAbs().maxCoeff());
    }
  };
  double t0, r0, q0;
  errors(&t0, &r0, &q0);

  ceres::Solver::Options options;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  options.max_num_iterations = 100;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_EQ(summary.termination_type, ceres::CONVERGENCE);

  double t1, r1, q1;
  errors(&t1, &r1, &q1);
  std::cout << "JointProblem (DOGLEG): " << summary.iterations.size() - 1 << " iterations, cost "
            << summary.initial_cost << " -> " << summary.final_cost << " (" << summary.num_residuals
            << " residuals)\n"
            << "  max pose translation error " << t0 << " -> " << t1 << " m, rotation " << r0
            << " -> " << r1 << " rad; max quadric minimal error " << q0 << " -> " << q1 << "\n"
            << "  " << summary.BriefReport() << "\n";
  RecordProperty("iterations", static_cast<int>(summary.iterations.size() - 1));
  EXPECT_LT(t1, 0.03);
  EXPECT_LT(r1, 0.02);
  EXPECT_LT(q1, 0.03);
  // Whitened residuals at the solution are noise-sized: 2*cost ~ chi^2 with ~ (residuals - params)
  // dof.
  EXPECT_LT(2 * summary.final_cost, 2.0 * summary.num_residuals);
}

}  // namespace
}  // namespace quadric_slam
