#include "quadric_slam/eval/stage_timing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace quadric_slam {

double percentile(std::vector<double> values, double q) {
  if (values.empty())
    return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size());
  const std::size_t index =
      std::min(values.size() - 1, static_cast<std::size_t>(std::max(1.0, std::ceil(rank))) - 1);
  return values[index];
}

TimingSummary summarize(const std::vector<double>& durations_ms) {
  TimingSummary s;
  s.count = durations_ms.size();
  if (durations_ms.empty())
    return s;
  s.median_ms = percentile(durations_ms, 0.5);
  s.p95_ms = percentile(durations_ms, 0.95);
  s.max_ms = *std::max_element(durations_ms.begin(), durations_ms.end());
  s.mean_ms = std::accumulate(durations_ms.begin(), durations_ms.end(), 0.0) / durations_ms.size();
  return s;
}

DurationReservoir::DurationReservoir(std::size_t capacity)
    : capacity_(std::max<std::size_t>(1, capacity)) {}

void DurationReservoir::add(double duration_ms) {
  ++count_;
  sum_ += duration_ms;
  max_ = count_ == 1 ? duration_ms : std::max(max_, duration_ms);
  if (sample_.size() < capacity_) {
    sample_.push_back(duration_ms);
    return;
  }
  // Algorithm R: the n-th duration replaces a random kept one with probability capacity / n.
  random_state_ = random_state_ * 6364136223846793005ULL + 1442695040888963407ULL;  // 64-bit LCG
  const std::size_t slot = static_cast<std::size_t>((random_state_ >> 11) % count_);
  if (slot < capacity_)
    sample_[slot] = duration_ms;
}

void DurationReservoir::merge(const DurationReservoir& other) {
  if (other.count_ == 0)
    return;
  const std::size_t count = count_ + other.count_;
  const double sum = sum_ + other.sum_;
  const double max = count_ == 0 ? other.max_ : std::max(max_, other.max_);
  for (const double d : other.sample_)
    add(d);
  count_ = count;
  sum_ = sum;
  max_ = max;
}

TimingSummary DurationReservoir::summary() const {
  TimingSummary s = summarize(sample_);
  s.count = count_;
  s.max_ms = max_;
  s.mean_ms = count_ > 0 ? sum_ / static_cast<double>(count_) : 0.0;
  return s;
}

std::map<std::string, TimingSummary> StageTimer::summaries() const {
  std::map<std::string, TimingSummary> out;
  for (const auto& [stage, durations] : stages_)
    out[stage] = durations.summary();
  return out;
}

std::string StageTimer::json(std::size_t frames, double wall_s) const {
  std::ostringstream out;
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "{\"frames\": %zu, \"wall_s\": %.3f, \"stages\": {", frames,
                wall_s);
  out << buffer;
  bool first = true;
  for (const auto& [stage, s] : summaries()) {
    std::snprintf(buffer, sizeof(buffer),
                  "%s\n  \"%s\": {\"median_ms\": %.3f, \"p95_ms\": %.3f, \"max_ms\": %.3f, "
                  "\"mean_ms\": %.3f, \"count\": %zu}",
                  first ? "" : ",", stage.c_str(), s.median_ms, s.p95_ms, s.max_ms, s.mean_ms,
                  s.count);
    out << buffer;
    first = false;
  }
  out << "\n}}\n";
  return out.str();
}

std::string StageTimer::table() const {
  std::ostringstream out;
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "%-14s %7s %10s %10s %10s\n", "stage", "frames",
                "median_ms", "p95_ms", "max_ms");
  out << buffer;
  for (const auto& [stage, s] : summaries()) {
    std::snprintf(buffer, sizeof(buffer), "%-14s %7zu %10.2f %10.2f %10.2f\n", stage.c_str(),
                  s.count, s.median_ms, s.p95_ms, s.max_ms);
    out << buffer;
  }
  return out.str();
}

}  // namespace quadric_slam
