// Per-stage wall-clock timing of a pipeline run: durations per named stage, summarised as median,
// p95 and max, written as the runner's timing.json.
#pragma once

#include <chrono>
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
  void add(const std::string& stage, double duration_ms) { stages_[stage].push_back(duration_ms); }
  // Appends another timer's durations (e.g. the reader's to the pipeline's).
  void merge(const StageTimer& other) {
    for (const auto& [stage, durations] : other.stages_)
      stages_[stage].insert(stages_[stage].end(), durations.begin(), durations.end());
  }

  std::map<std::string, TimingSummary> summaries() const;
  // {"frames": N, "wall_s": X, "stages": {"name": {"median_ms": .., "p95_ms": .., "max_ms": ..,
  //  "mean_ms": .., "count": ..}, ...}}
  std::string json(std::size_t frames, double wall_s) const;
  // One line per stage: name, count, median, p95, max (ms).
  std::string table() const;

 private:
  std::map<std::string, std::vector<double>> stages_;
};

}  // namespace quadric_slam
