// Splits [0, count) into `threads` contiguous chunks and runs fn(chunk, begin, end) on each, the
// first on the calling thread; returns the number of chunks. For row-parallel image passes.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace quadric_slam {

template <typename Fn>
int forEachChunk(int count, int threads, Fn fn) {
  threads = std::max(1, std::min(threads, count));
  std::vector<std::thread> workers;
  for (int t = 1; t < threads; ++t)
    workers.emplace_back(fn, t, count * t / threads, count * (t + 1) / threads);
  fn(0, 0, count / threads);
  for (auto& worker : workers)
    worker.join();
  return threads;
}

}  // namespace quadric_slam
