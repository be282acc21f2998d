#include "quadric_slam/ros/drop_reporter.h"

#include <ros/console.h>

#include "quadric_slam/ros/diagnostics.h"

namespace quadric_slam {

ReasonThrottle::ReasonThrottle(double period_s, std::size_t max_reasons)
    : period_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s))),
      max_reasons_(max_reasons) {}

bool ReasonThrottle::allow(const std::string& reason, Clock::time_point now,
                           unsigned long* suppressed) {
  // Forget the reasons whose period is over: they may be logged again, and the table stays small.
  for (auto it = last_logged_.begin(); it != last_logged_.end();) {
    it = now - it->second >= period_ ? last_logged_.erase(it) : std::next(it);
  }
  if (last_logged_.count(reason) || last_logged_.size() >= max_reasons_) {
    ++suppressed_;
    return false;
  }
  last_logged_[reason] = now;
  if (suppressed)
    *suppressed = suppressed_;
  suppressed_ = 0;
  return true;
}

DropReporter::DropReporter(std::string prefix, NodeletDiagnostics* diagnostics, double period_s)
    : prefix_(std::move(prefix)), diagnostics_(diagnostics), throttle_(period_s) {}

void DropReporter::drop(const std::string& reason) noexcept {
  report(reason);
  try {
    if (diagnostics_)
      diagnostics_->frameDropped(reason);
  } catch (...) {
    // Nothing left to report with: the frame is dropped all the same.
  }
}

void DropReporter::report(const std::string& reason) noexcept {
  try {
    unsigned long suppressed = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!throttle_.allow(reason, ReasonThrottle::Clock::now(), &suppressed))
        return;
    }
    if (suppressed > 0) {
      ROS_ERROR("%s: %s (%lu repeated or other reports suppressed in the last period)",
                prefix_.c_str(), reason.c_str(), suppressed);
    } else {
      ROS_ERROR("%s: %s", prefix_.c_str(), reason.c_str());
    }
  } catch (...) {
    // Logging itself failed (out of memory): nothing left to report with.
  }
}

}  // namespace quadric_slam
