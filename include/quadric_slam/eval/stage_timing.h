// Per-stage wall-clock timing of a pipeline run: durations per named stage, summarised as median,
// p95 and max, written as the runner's timing.json. Memory stays bounded however long the run.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace quadric_slam {

struct TimingSummary {
  std::size_t count = 0;
  double median_ms = 0, p95_ms = 0, max_ms = 0, mean_ms = 0;
};

// Nearest-rank percentile (q in [0, 1]) of unsorted values; 0 for none.
double percentile(std::vector<double> values, double q);
TimingSummary summarize(const std::vector<double>& durations_ms);

// The durations of one stage, in bounded memory: every duration up to `capacity`, then a uniform
// random sample of that size of all of them (reservoir sampling, Vitter's algorithm R, seeded so a
// run is repeatable); count, mean and max stay exact. Percentiles over a sample of 20,000 are
// within a fraction of a percentile rank of the exact ones, and an hour-long run keeps a constant
// footprint.
class DurationReservoir {
 public:
  explicit DurationReservoir(std::size_t capacity = 20000);
  void add(double duration_ms);
  // Adds every duration of other (its sample, when other has gone beyond its capacity), keeping
  // other's exact count, sum and max.
  void merge(const DurationReservoir& other);
  TimingSummary summary() const;
  std::size_t count() const { return count_; }
  const std::vector<double>& sample() const { return sample_; }

 private:
  std::size_t capacity_;
  std::vector<double> sample_;
  std::size_t count_ = 0;
  double sum_ = 0.0, max_ = 0.0;
  std::uint64_t random_state_ = 0x9E3779B97F4A7C15ULL;
};

class StageTimer {
 public:
  // Times fn() under the stage's name and returns what it returns.
  template <typename Fn>
  auto time(const std::string& stage, Fn&& fn) {
    const auto start = std::chrono::steady_clock::now();
    struct Record {
      StageTimer* timer;
      const std::string& stage;
      std::chrono::steady_clock::time_point start;
      ~Record() {
        timer->add(stage, std::chrono::duration<double, std::milli>(
                              std::chrono::steady_clock::now() - start)
                              .count());
      }
    } record{this, stage, start};
    return fn();
  }
  void add(const std::string& stage, double duration_ms) { stages_[stage].add(duration_ms); }
  // Appends another timer's durations (e.g. the reader's to the pipeline's).
  void merge(const StageTimer& other) {
    for (const auto& [stage, durations] : other.stages_)
      stages_[stage].merge(durations);
  }

  std::map<std::string, TimingSummary> summaries() const;
  // {"frames": N, "wall_s": X, "stages": {"name": {"median_ms": .., "p95_ms": .., "max_ms": ..,
  //  "mean_ms": .., "count": ..}, ...}}
  std::string json(std::size_t frames, double wall_s) const;
  // One line per stage: name, count, median, p95, max (ms).
  std::string table() const;

 private:
  std::map<std::string, DurationReservoir> stages_;
};

}  // namespace quadric_slam
