// Memory of this process, for long-run curves and diagnostics (Linux /proc, glibc malloc).
#pragma once

#include <cstddef>

namespace quadric_slam {

// Resident set size (bytes) of this process from /proc/self/statm; 0 when unavailable.
std::size_t residentMemoryBytes();

// What the C heap holds, over every malloc arena (glibc mallinfo2; zeros elsewhere).
// in_use is what the program has allocated and not freed: it follows the data (the map, the
// frames in flight). held_free is freed memory the allocator keeps for reuse: it is where a
// resident size that grows while in_use stays flat comes from.
struct HeapUsage {
  std::size_t in_use = 0;
  std::size_t held_free = 0;
};
HeapUsage heapUsage();

// Returns the heap's free pages to the kernel (glibc malloc_trim; nothing elsewhere). Worth it
// after freeing a large buffer of a size that keeps growing (a whole-map point cloud): glibc
// raises its mmap threshold after such a free, so the next, larger buffer comes from an arena
// of the calling thread and the holes left behind stay resident. Costs about a millisecond per
// hundred megabytes of heap; call it after the occasional large publication, not per frame.
void releaseFreeHeapMemory();

}  // namespace quadric_slam
