// Resident memory of a process, for long-run curves (Linux /proc).
#pragma once

#include <cstddef>

namespace quadric_slam {

// Resident set size (bytes) of this process from /proc/self/statm; 0 when unavailable.
std::size_t residentMemoryBytes();

}  // namespace quadric_slam
