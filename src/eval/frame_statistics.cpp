#include "quadric_slam/eval/frame_statistics.h"

#include <stdexcept>

namespace quadric_slam {

FrameStatistics::FrameStatistics(std::size_t timing_window, std::size_t max_reasons)
    : durations_(timing_window), max_reasons_(max_reasons) {
  if (max_reasons_ == 0)
    throw std::invalid_argument("FrameStatistics: max_reasons must be >= 1");
}

void FrameStatistics::processed(double processing_ms) {
  ++processed_;
  durations_.add(processing_ms);
}

void FrameStatistics::dropped(const std::string& reason) {
  ++dropped_;
  last_drop_reason_ = reason;
  auto it = drops_per_reason_.find(reason);
  if (it != drops_per_reason_.end())
    ++it->second;
  else if (drops_per_reason_.size() < max_reasons_)
    drops_per_reason_.emplace(reason, 1);
  else
    ++drops_per_reason_[kOtherReasons];
}

FrameStatistics::Period FrameStatistics::takePeriod() {
  const Period period{processed_ - reported_.processed, dropped_ - reported_.dropped};
  reported_ = Period{processed_, dropped_};
  return period;
}

}  // namespace quadric_slam
