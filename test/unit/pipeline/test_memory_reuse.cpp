// keepFreedMemoryForReuse: a frame-sized block comes from the heap and stays there once freed, so
// the next frame's buffers reuse its pages instead of faulting in new ones.
#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdlib>
#include <cstring>

#include "quadric_slam/pipeline/memory_reuse.h"

namespace qs = quadric_slam;

TEST(MemoryReuse, AFrameSizedBlockIsKeptForTheNextFrame) {
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") != nullptr ||
      std::getenv("MALLOC_TRIM_THRESHOLD_") != nullptr)
    GTEST_SKIP() << "the allocator is configured from the environment";
  // A 640 x 480 cloud with normals (pcl::PointNormal, 48 bytes a point).
  constexpr std::size_t kFrameBytes = 640 * 480 * 48;

  // glibc's defaults: such a block is mapped for itself and unmapped when freed.
  const std::size_t mapped_before = mallinfo2().hblkhd;
  void* block = std::malloc(kFrameBytes);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, kFrameBytes);
  EXPECT_GE(mallinfo2().hblkhd, mapped_before + kFrameBytes);
  std::free(block);

  ASSERT_TRUE(qs::keepFreedMemoryForReuse());
  const std::size_t mapped = mallinfo2().hblkhd;
  block = std::malloc(kFrameBytes);
  ASSERT_NE(block, nullptr);
  std::memset(block, 1, kFrameBytes);
  EXPECT_EQ(mallinfo2().hblkhd, mapped) << "the block was mapped for itself";
  std::free(block);
  EXPECT_GE(mallinfo2().fordblks, kFrameBytes) << "the freed block left the process";
}
