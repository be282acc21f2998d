// The segmentation's Levenberg-Marquardt damping and stopping rule
// (frontend/levenberg_marquardt.h): Nielsen's gain-ratio update, the linear model's
// predicted decrease, the variance tolerance; a cone's refinement stopped by it within a fraction
// of a standard deviation of its optimum.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>

#include "axial_surface_samples.h"
#include "quadric_slam/frontend/levenberg_marquardt.h"
#include "quadric_slam/frontend/shape_refiner.h"

namespace qs = quadric_slam;

TEST(LevenbergMarquardtDamping, GainRatioLowersOrRaisesLambda) {
  qs::LevenbergMarquardtDamping damping(1e-3);
  damping.accepted(1.0, 1.0);  // the model held: lambda / 3
  EXPECT_NEAR(damping.lambda, 1e-3 / 3, 1e-12);
  damping.accepted(0.5, 1.0);  // half the predicted gain: unchanged
  EXPECT_NEAR(damping.lambda, 1e-3 / 3, 1e-12);
  damping.accepted(1e-9, 1.0);  // almost no gain: about x 2
  EXPECT_NEAR(damping.lambda, 2e-3 / 3, 1e-9);
  damping.rejected();
  damping.rejected();  // x 2, then x 4
  EXPECT_NEAR(damping.lambda, 16e-3 / 3, 1e-9);
  damping.accepted(1.0, 1.0);  // the growth starts again at 2
  damping.rejected();
  EXPECT_NEAR(damping.lambda, 2 * 16e-3 / 9, 1e-9);
  qs::LevenbergMarquardtDamping floor(1e-9);
  floor.accepted(1.0, 1.0);
  EXPECT_EQ(floor.lambda, qs::LevenbergMarquardtDamping::kMinLambda);
}

TEST(LevenbergMarquardtDamping, PredictedDecreaseIsExactForLinearResiduals) {
  const Eigen::MatrixXd J = Eigen::MatrixXd::Random(20, 4);
  const Eigen::VectorXd r = Eigen::VectorXd::Random(20);
  const Eigen::VectorXd delta = Eigen::VectorXd::Random(4) * 0.3;
  const Eigen::MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd g = J.transpose() * r;
  const double actual = r.squaredNorm() - (r + J * delta).squaredNorm();
  EXPECT_NEAR(qs::predictedDecrease(H, g, delta), actual, 1e-9);
}

TEST(LevenbergMarquardtDamping, ConvergedWithinNoiseComparesWithTheResidualVariance) {
  // 102 points, 2 parameters, cost 100: residual variance 1.
  EXPECT_TRUE(qs::convergedWithinNoise(0.05, 100.0, 102, 2, 0.1));
  EXPECT_FALSE(qs::convergedWithinNoise(0.2, 100.0, 102, 2, 0.1));
  EXPECT_FALSE(qs::convergedWithinNoise(0.05, 100.0, 102, 2, 0.0));  // off
}

TEST(ShapeRefiner, VarianceToleranceStopsWithinAFractionOfASigma) {
  // A cone seen from one side at 1.6 m with 3 mm noise, refined from a start tilted by 0.1 rad and
  // 5 cm off: stopped by the variance tolerance, against the same refinement run to convergence.
  const qs::test::SurfaceSamples samples = qs::test::axialSurface(true, 0.3, 0.25, 0.45, 0.003, 7);
  const qs::PrimitiveShape start =
      qs::PrimitiveShape::cone(qs::test::kAxisPoint + Eigen::Vector3d(0.05, 0.0, 0.0),
                               Eigen::Vector3d(0.1, 1.0, 0.0).normalized(), 0.35);
  qs::ShapeRefiner::Params converged_params;
  converged_params.max_iterations = 100;
  converged_params.relative_tolerance = 1e-12;
  converged_params.variance_tolerance = 0.0;
  const qs::ShapeRefiner::Result converged =
      qs::ShapeRefiner(converged_params).refine(start, samples.points);
  qs::ShapeRefiner::Params early_params = converged_params;
  early_params.variance_tolerance = 0.1;
  const qs::ShapeRefiner::Result early =
      qs::ShapeRefiner(early_params).refine(start, samples.points);
  // Stopped after a single step, the fit is far from its optimum (the comparison can tell).
  qs::ShapeRefiner::Params one_step_params = converged_params;
  one_step_params.max_iterations = 1;
  const qs::ShapeRefiner::Result one_step =
      qs::ShapeRefiner(one_step_params).refine(start, samples.points);
  ASSERT_TRUE(converged.ok);
  ASSERT_TRUE(early.ok);
  ASSERT_TRUE(one_step.ok);
  // Differences in the minimal coordinates, against the converged fit's covariance.
  const auto sigmas = [&](const qs::ShapeRefiner::Result& fit) {
    const Eigen::VectorXd d = fit.shape.quadric().minusMinimal(converged.shape.quadric());
    return std::sqrt(d.dot(converged.covariance.ldlt().solve(d)));
  };
  EXPECT_LT(sigmas(early), 0.5);
  EXPECT_GT(sigmas(one_step), 10.0);
  EXPECT_NEAR(early.rms, converged.rms, 1e-3 * converged.rms);
}

TEST(ShapeRefiner, VarianceToleranceIsValidated) {
  qs::ShapeRefiner::Params params;
  params.variance_tolerance = -0.1;
  EXPECT_THROW(qs::ShapeRefiner{params}, std::invalid_argument);
  params.variance_tolerance = 1.5;
  EXPECT_THROW(qs::ShapeRefiner{params}, std::invalid_argument);
}
