// Parallel loops of the segmentation: forEachChunk for row-parallel image passes, forEachTask for
// independent tasks of uneven cost.
#pragma once

#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

namespace quadric_slam {

// Splits [0, count) into `threads` contiguous chunks and runs fn(chunk, begin, end) on each, the
// first on the calling thread; returns the number of chunks.
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

// Runs task(i) for every i in [0, count) on up to `threads` threads (one of them the calling
// thread), each taking the next index when it is done with one. What task(i) throws goes to
// on_error(i, std::exception_ptr) on the thread that ran it (an exception must not leave a
// std::thread).
template <typename Task, typename OnError>
void forEachTask(int count, int threads, Task task, OnError on_error) {
  std::atomic<int> next{0};
  forEachChunk(std::min(threads, count), std::min(threads, count), [&](int, int, int) {
    for (int i = next++; i < count; i = next++) {
      try {
        task(i);
      } catch (...) {
        on_error(i, std::current_exception());
      }
    }
  });
}

}  // namespace quadric_slam
