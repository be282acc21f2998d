// observationVarianceFactor: whitened residuals drawn with a known variance factor give it back,
// over residuals of mixed dimensions; gross outliers barely move it; honest or better-than-stated
// residuals give 1 (never below).
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "quadric_slam/mapping/observation_noise_scale.h"

namespace quadric_slam {
namespace {

// n residuals of dimension k whose components are N(0, factor): |r|^2 = factor chi2_k.
void draw(int k, double factor, int n, std::mt19937* rng, std::vector<WhitenedResidual>* out) {
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int i = 0; i < n; ++i) {
    double squared = 0.0;
    for (int j = 0; j < k; ++j) {
      const double x = gauss(*rng);
      squared += x * x;
    }
    out->push_back({k, factor * squared});
  }
}

TEST(ObservationVarianceFactor, RecoversTheFactorOverMixedDimensions) {
  std::mt19937 rng(5);
  std::vector<WhitenedResidual> residuals;
  for (int k : {3, 4, 5, 6, 9})
    draw(k, 400.0, 1000, &rng, &residuals);
  EXPECT_NEAR(observationVarianceFactor(residuals), 400.0, 20.0);
}

TEST(ObservationVarianceFactor, NeverBelowOne) {
  std::mt19937 rng(6);
  for (double truth : {1.0, 0.25}) {
    std::vector<WhitenedResidual> residuals;
    draw(3, truth, 4000, &rng, &residuals);
    const double factor = observationVarianceFactor(residuals);
    EXPECT_GE(factor, 1.0) << truth;
    EXPECT_LT(factor, 1.1) << truth;
  }
}

TEST(ObservationVarianceFactor, GrossOutliersBarelyMoveIt) {
  std::mt19937 rng(7);
  std::vector<WhitenedResidual> residuals;
  draw(3, 100.0, 900, &rng, &residuals);
  draw(3, 1e6, 100, &rng, &residuals);  // 10 % wrong associations
  // The median of the contaminated set sits at the 55.6 % point of the clean one: about 1.18 x.
  const double factor = observationVarianceFactor(residuals);
  EXPECT_GT(factor, 100.0);
  EXPECT_LT(factor, 130.0);
}

TEST(ObservationVarianceFactor, EmptyAndInvalidInput) {
  EXPECT_EQ(observationVarianceFactor({}), 1.0);
  EXPECT_THROW(observationVarianceFactor({{0, 1.0}}), std::invalid_argument);
}

}  // namespace
}  // namespace quadric_slam
