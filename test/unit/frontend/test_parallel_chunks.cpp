// forEachChunk and forEachTask (frontend/parallel_chunks.h): every index runs once, whatever the
// number of threads, and an exception reaches on_error instead of ending the process.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <vector>

#include "quadric_slam/frontend/parallel_chunks.h"

namespace quadric_slam {
namespace {

TEST(ParallelChunks, ChunksCoverTheRangeOnceInOrder) {
  for (int threads : {1, 2, 3, 8}) {
    std::vector<int> hits(10, 0);
    const int chunks = forEachChunk(10, threads, [&](int, int begin, int end) {
      for (int i = begin; i < end; ++i)
        ++hits[i];
    });
    EXPECT_EQ(chunks, std::min(threads, 10));
    EXPECT_EQ(hits, std::vector<int>(10, 1)) << threads << " threads";
  }
}

TEST(ParallelChunks, EveryTaskRunsOnceAndItsExceptionGoesToOnError) {
  for (int threads : {1, 2, 4, 64}) {
    std::vector<std::atomic<int>> runs(25);
    std::vector<int> failed(25, 0);
    forEachTask(
        25, threads,
        [&](int i) {
          ++runs[i];
          if (i % 7 == 3)
            throw std::runtime_error("task " + std::to_string(i));
        },
        [&](int i, std::exception_ptr error) {
          ASSERT_TRUE(error);
          failed[i] = 1;
        });
    for (int i = 0; i < 25; ++i) {
      EXPECT_EQ(runs[i].load(), 1) << i << ", " << threads << " threads";
      EXPECT_EQ(failed[i], i % 7 == 3 ? 1 : 0) << i;
    }
  }
  int calls = 0;
  forEachTask(
      0, 4, [&](int) { ++calls; }, [&](int, std::exception_ptr) { ++calls; });
  EXPECT_EQ(calls, 0);
}

}  // namespace
}  // namespace quadric_slam
