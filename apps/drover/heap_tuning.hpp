#pragma once
// glibc heap settings for a process that allocates and frees megabyte buffers every sweep (deskewed scans, feature
// clouds, k-d trees, local maps). By default glibc serves blocks above its mmap threshold with fresh mmap()s and
// hands freed heap tops back to the kernel, so every sweep page-faults its buffers in again; on a machine where
// fresh pages are expensive that halved the HDL-64 rate (2.6x instead of 5.5x real time, bench/RESULTS.md). With a
// 32 MiB mmap threshold (glibc's maximum) and a 1 GiB trim threshold freed buffers stay in the heap for the next
// sweep. Peak RSS is what the program needs at its peak either way; only the return of memory after a peak waits.
// The app's concern, not the libraries': the core never touches the allocator.
// C++17 on purpose: drover_ros's main includes it (see apps/drover_ros/live_session.hpp).
#include <malloc.h>

#include <chrono>
#include <cstdint>

namespace drover::cli {

inline void tuneHeapForSweeps() {
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);  // [bytes] glibc's upper limit on 64-bit
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);  // [bytes]
}

// Hands the heap's free pages back to the kernel once every `period` (malloc_trim: madvise on the free pages of every
// arena; the blocks stay where they are). A run that also grows its map between the per-sweep buffers fragments the
// heap, and with the settings above nothing freed is ever returned: over six laps of the farm (65 min) the free store
// grew by 18 MB on top of the 64 MB one lap needs (bench_memory_hour, bench/RESULTS.md). Once per period the next
// sweeps fault their buffers in again -- milliseconds every 30 s, not the per-sweep cost tuneHeapForSweeps avoids.
class HeapTrimmer {
 public:
  static constexpr std::int64_t kDefaultPeriod = 30'000'000'000;  // [ns]
  explicit HeapTrimmer(std::int64_t period_ns = kDefaultPeriod) : period_(period_ns) {}
  // `now` [ns]: data time in a replay, wall time live; true when it trimmed. The first call only starts the clock,
  // and so does a jump back by more than a period (a clock jump); a smaller step back (a sweep stamped at its start
  // after the IMU samples of its revolution) is ignored, so it neither trims nor holds the next trim off.
  bool tick(std::int64_t now) {
    if (!started_ || now < last_ - period_) {
      started_ = true;
      last_ = now;
      return false;
    }
    if (now - last_ < period_) return false;
    last_ = now;
    const auto t0 = std::chrono::steady_clock::now();
    malloc_trim(0);
    trim_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++trims_;
    return true;
  }
  std::int64_t trims() const { return trims_; }
  double trimSeconds() const { return trim_s_; }  // [s] of wall time spent in malloc_trim

 private:
  std::int64_t period_;
  std::int64_t last_ = 0;
  std::int64_t trims_ = 0;
  double trim_s_ = 0.0;
  bool started_ = false;
};

}  // namespace drover::cli
