// What happened to the frames a stage received: processed (with the processing time of the recent
// ones) or dropped (counted per reason). Memory stays bounded over long runs: the timing covers a
// window of recent frames and at most max_reasons distinct drop reasons are kept apart (later ones
// are counted together, since a reason may carry frame-specific text).
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include "quadric_slam/eval/recent_durations.h"

namespace quadric_slam {

class FrameStatistics {
 public:
  // The key that collects drops once max_reasons distinct reasons are held.
  static constexpr const char* kOtherReasons = "(other reasons)";

  explicit FrameStatistics(std::size_t timing_window = 300, std::size_t max_reasons = 16);

  void processed(double processing_ms);
  void dropped(const std::string& reason);

  std::size_t received() const { return processed_ + dropped_; }
  std::size_t processedCount() const { return processed_; }
  std::size_t droppedCount() const { return dropped_; }
  const std::map<std::string, std::size_t>& dropsPerReason() const { return drops_per_reason_; }
  const std::string& lastDropReason() const { return last_drop_reason_; }
  // Processing time over the recent window.
  TimingSummary timing() const { return durations_.summary(); }

  // Frames processed and dropped since the previous call (a reporting period).
  struct Period {
    std::size_t processed = 0, dropped = 0;
  };
  Period takePeriod();

 private:
  RecentDurations durations_;
  std::size_t max_reasons_;
  std::size_t processed_ = 0, dropped_ = 0;
  std::map<std::string, std::size_t> drops_per_reason_;
  std::string last_drop_reason_;
  Period reported_;  // the totals at the previous takePeriod()
};

}  // namespace quadric_slam
