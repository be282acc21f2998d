#pragma once

namespace quadric_slam {

// Asks the C library's allocator to keep freed memory in the process for the next frame instead
// of handing it back to the kernel. Each frame allocates and frees clouds of several megabytes
// (the back-projected points, the segmenter's decimated grid, the depth in metres); by default
// glibc returns them (mmap for large blocks, heap trimming), and every page of the next frame's
// buffers faults in again: about 1000 page faults per 640 x 480 frame, 15 % of the pipeline's CPU
// time on a virtual machine, where a fault costs several microseconds. The resident memory then
// stays at its high-water mark.
//
// Settings from the environment (MALLOC_MMAP_THRESHOLD_, MALLOC_TRIM_THRESHOLD_) win: they are
// left alone when present. Returns false when the allocator is not glibc's or refused.
bool keepFreedMemoryForReuse();

}  // namespace quadric_slam
