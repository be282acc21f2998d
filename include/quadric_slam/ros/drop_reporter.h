// How a nodelet reports input it cannot use: a throttled error on rosout per distinct reason (one
// reason's throttle never hides another), the drop counted on /diagnostics, and a guard that turns
// whatever a callback body throws into such a drop, so no message can terminate the manager.
#pragma once

#include <chrono>
#include <exception>
#include <mutex>
#include <string>
#include <unordered_map>

namespace quadric_slam {

class NodeletDiagnostics;

// Decides which reasons to log: each distinct reason at most once per period, and at most
// max_reasons distinct ones per period (a stream of ever-different reasons, e.g. corrupted sizes,
// cannot flood rosout); the refused ones are counted and reported with the next logged one.
class ReasonThrottle {
 public:
  using Clock = std::chrono::steady_clock;

  explicit ReasonThrottle(double period_s = 5.0, std::size_t max_reasons = 20);

  // True when reason should be logged now; then *suppressed (when given) receives the number of
  // reports refused since the last one logged.
  bool allow(const std::string& reason, Clock::time_point now, unsigned long* suppressed = nullptr);

 private:
  Clock::duration period_;
  std::size_t max_reasons_;
  std::unordered_map<std::string, Clock::time_point> last_logged_;
  unsigned long suppressed_ = 0;
};

class DropReporter {
 public:
  // prefix starts every line, e.g. "normal_estimation: dropping depth frame"; diagnostics (may be
  // null) counts each drop.
  DropReporter(std::string prefix, NodeletDiagnostics* diagnostics, double period_s = 5.0);

  // Logs "<prefix>: <reason>" (throttled per reason) and counts a dropped frame.
  void drop(const std::string& reason) noexcept;
  // Logs "<prefix>: <reason>" (throttled per reason) without counting a frame.
  void report(const std::string& reason) noexcept;

  // Runs body(); anything it throws becomes drop("unexpected error: ..."). roscpp does not catch
  // what a callback throws: the manager, and every nodelet in it, would die.
  template <typename Body>
  void guard(Body&& body) noexcept {
    try {
      body();
    } catch (const std::exception& e) {
      drop(std::string("unexpected error: ") + e.what());
    } catch (...) {
      drop("unexpected error of an unknown type");
    }
  }

 private:
  std::string prefix_;
  NodeletDiagnostics* diagnostics_;
  std::mutex mutex_;
  ReasonThrottle throttle_;
};

}  // namespace quadric_slam
