#include "quadric_slam/eval/recent_durations.h"

#include <stdexcept>

namespace quadric_slam {

RecentDurations::RecentDurations(std::size_t capacity) : capacity_(capacity) {
  if (capacity_ == 0)
    throw std::invalid_argument("RecentDurations: the capacity must be >= 1");
  window_.reserve(capacity_);
}

void RecentDurations::add(double duration_ms) {
  ++total_;
  if (window_.size() < capacity_) {
    window_.push_back(duration_ms);
    return;
  }
  window_[next_] = duration_ms;
  next_ = (next_ + 1) % capacity_;
}

TimingSummary RecentDurations::summary() const { return summarize(window_); }

void RecentDurations::clear() {
  window_.clear();
  next_ = 0;
  total_ = 0;
}

}  // namespace quadric_slam
