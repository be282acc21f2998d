// The durations of the most recent frames of a long-running stage (a nodelet runs for hours):
// a fixed-capacity ring, so memory stays bounded, summarised like the offline runner's timing
// (median, p95, max, mean of the window) plus the total count since the start.
#pragma once

#include <cstddef>
#include <vector>

#include "quadric_slam/eval/stage_timing.h"

namespace quadric_slam {

class RecentDurations {
 public:
  // capacity: how many of the latest durations the summary covers (>= 1).
  explicit RecentDurations(std::size_t capacity = 300);

  void add(double duration_ms);
  // Over the window (count = durations in it, at most the capacity).
  TimingSummary summary() const;
  // Every duration ever added, also those that left the window.
  std::size_t total() const { return total_; }
  std::size_t capacity() const { return capacity_; }
  void clear();

 private:
  std::size_t capacity_;
  std::vector<double> window_;  // grows to capacity_, then is overwritten oldest first
  std::size_t next_ = 0;        // where the next duration goes once the window is full
  std::size_t total_ = 0;
};

}  // namespace quadric_slam
