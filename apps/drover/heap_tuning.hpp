#pragma once
// glibc heap settings for a process that allocates and frees megabyte buffers every sweep (deskewed scans, feature
// clouds, k-d trees, local maps). By default glibc serves blocks above its mmap threshold with fresh mmap()s and
// hands freed heap tops back to the kernel, so every sweep page-faults its buffers in again; on a machine where
// fresh pages are expensive that halved the HDL-64 rate (2.6x instead of 5.5x real time, bench/RESULTS.md). With a
// 32 MiB mmap threshold (glibc's maximum) and a 1 GiB trim threshold freed buffers stay in the heap for the next
// sweep. Peak RSS is what the program needs at its peak either way; only the return of memory after a peak waits.
// The app's concern, not the libraries': the core never touches the allocator.
#include <malloc.h>

namespace drover::cli {

inline void tuneHeapForSweeps() {
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);  // [bytes] glibc's upper limit on 64-bit
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);  // [bytes]
}

}  // namespace drover::cli
