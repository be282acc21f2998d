// Timestamp association exactly as TUM's associate.py (used by evaluate_ate.py and to pair RGB with
// depth): every candidate pair with |a - (b + offset)| < max_difference, sorted by that difference
// (ties by a, then b), taken greedily so each stamp is used at most once; result sorted by a.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace quadric_slam {

struct StampAssociationParams {
  double offset = 0.0;           // added to the second list's stamps before comparing (s)
  double max_difference = 0.02;  // pairs must differ by strictly less than this (s)

  // Throws std::invalid_argument naming the bad field and its allowed range.
  void validate() const;
};

// Index pairs (i into first, j into second). Stamps need not be sorted; duplicate stamps within a
// list are the caller's business (associate.py works on dicts, so it never sees duplicates).
std::vector<std::pair<std::size_t, std::size_t>> associateStamps(
    const std::vector<double>& first, const std::vector<double>& second,
    const StampAssociationParams& params);

}  // namespace quadric_slam
