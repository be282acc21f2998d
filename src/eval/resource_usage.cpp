#include "quadric_slam/eval/resource_usage.h"

#include <unistd.h>

#include <fstream>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace quadric_slam {

std::size_t residentMemoryBytes() {
  // statm: total program size, then resident pages (proc(5)).
  std::ifstream statm("/proc/self/statm");
  std::size_t total_pages = 0, resident_pages = 0;
  if (!(statm >> total_pages >> resident_pages))
    return 0;
  const long page = sysconf(_SC_PAGESIZE);
  return page > 0 ? resident_pages * static_cast<std::size_t>(page) : 0;
}

HeapUsage heapUsage() {
  HeapUsage usage;
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
  const struct mallinfo2 info = mallinfo2();
  // uordblks: allocated from the arenas; hblkhd: allocated by mmap (large blocks).
  usage.in_use = info.uordblks + info.hblkhd;
  usage.held_free = info.fordblks;
#endif
  return usage;
}

void releaseFreeHeapMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace quadric_slam
