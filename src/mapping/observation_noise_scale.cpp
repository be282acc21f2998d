#include "quadric_slam/mapping/observation_noise_scale.h"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "quadric_slam/mapping/association.h"

namespace quadric_slam {

double observationVarianceFactor(const std::vector<WhitenedResidual>& residuals) {
  std::map<int, double> chi2_median;  // per dimension
  std::vector<double> ratios;
  ratios.reserve(residuals.size());
  for (const WhitenedResidual& r : residuals) {
    if (r.dimension < 1)
      throw std::invalid_argument("observationVarianceFactor: a residual of dimension < 1");
    auto m = chi2_median.find(r.dimension);
    if (m == chi2_median.end())
      m = chi2_median.emplace(r.dimension, chiSquareQuantile(r.dimension, 0.5)).first;
    ratios.push_back(r.squared_norm / m->second);
  }
  if (ratios.empty())
    return 1.0;
  const auto middle = ratios.begin() + ratios.size() / 2;
  std::nth_element(ratios.begin(), middle, ratios.end());
  return std::max(1.0, *middle);
}

}  // namespace quadric_slam
