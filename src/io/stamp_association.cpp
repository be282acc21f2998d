#include "quadric_slam/io/stamp_association.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <tuple>

namespace quadric_slam {

void StampAssociationParams::validate() const {
  if (!std::isfinite(offset)) {
    throw std::invalid_argument("offset must be finite (s), got " + std::to_string(offset));
  }
  if (!(max_difference > 0.0) || !std::isfinite(max_difference)) {
    throw std::invalid_argument("max_difference must be in (0, inf) s, got " +
                                std::to_string(max_difference));
  }
}

std::vector<std::pair<std::size_t, std::size_t>> associateStamps(
    const std::vector<double>& first, const std::vector<double>& second,
    const StampAssociationParams& params) {
  params.validate();
  // Candidate search over the second list sorted by stamp: the same candidates as associate.py's
  // all-pairs comprehension, found in O(n log n) instead of O(n m).
  std::vector<std::size_t> second_order(second.size());
  std::iota(second_order.begin(), second_order.end(), 0);
  std::sort(second_order.begin(), second_order.end(),
            [&](std::size_t x, std::size_t y) { return second[x] < second[y]; });
  std::vector<double> second_sorted(second.size());
  for (std::size_t k = 0; k < second.size(); ++k)
    second_sorted[k] = second[second_order[k]];

  // (difference, a, b, index of a, index of b), sorted like Python sorts (diff, a, b) tuples.
  std::vector<std::tuple<double, double, double, std::size_t, std::size_t>> candidates;
  for (std::size_t i = 0; i < first.size(); ++i) {
    const double a = first[i];
    // b + offset within (a - max_difference, a + max_difference); widen a little, then test
    // with associate.py's exact expression.
    const double low = a - params.offset - 2.0 * params.max_difference;
    auto it = std::lower_bound(second_sorted.begin(), second_sorted.end(), low);
    for (; it != second_sorted.end(); ++it) {
      const double b = *it;
      if (b > a - params.offset + 2.0 * params.max_difference)
        break;
      const double difference = std::abs(a - (b + params.offset));
      if (difference < params.max_difference) {
        const std::size_t j = second_order[static_cast<std::size_t>(it - second_sorted.begin())];
        candidates.emplace_back(difference, a, b, i, j);
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());

  std::vector<char> first_used(first.size(), 0), second_used(second.size(), 0);
  std::vector<std::pair<std::size_t, std::size_t>> matches;
  for (const auto& candidate : candidates) {
    const std::size_t i = std::get<3>(candidate), j = std::get<4>(candidate);
    if (first_used[i] || second_used[j])
      continue;
    first_used[i] = second_used[j] = 1;
    matches.emplace_back(i, j);
  }
  std::sort(matches.begin(), matches.end(), [&](const auto& x, const auto& y) {
    return std::make_pair(first[x.first], second[x.second]) <
           std::make_pair(first[y.first], second[y.second]);
  });
  return matches;
}

}  // namespace quadric_slam
