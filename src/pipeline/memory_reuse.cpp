#include "quadric_slam/pipeline/memory_reuse.h"

#include <cstdlib>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace quadric_slam {

bool keepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Blocks below 32 MiB (glibc's largest threshold; a 640 x 480 cloud with normals is 15 MB) come
  // from the heap, and the heap is trimmed only when 512 MiB lie free at its top. Fixing the mmap
  // threshold also ends glibc's dynamic threshold, which would otherwise move with the first frees.
  constexpr int kMmapThreshold = 32 << 20;
  constexpr int kTrimThreshold = 512 << 20;
  bool ok = true;
  if (std::getenv("MALLOC_MMAP_THRESHOLD_") == nullptr)
    ok = mallopt(M_MMAP_THRESHOLD, kMmapThreshold) == 1 && ok;
  if (std::getenv("MALLOC_TRIM_THRESHOLD_") == nullptr)
    ok = mallopt(M_TRIM_THRESHOLD, kTrimThreshold) == 1 && ok;
  return ok;
#else
  return false;
#endif
}

}  // namespace quadric_slam
