#pragma once
// main() for benchmarks of the per-sweep pipeline: the heap set up as `drover` sets it (apps/drover/heap_tuning.hpp),
// so freed sweep buffers stay in the heap and a benchmark measures the pipeline as the app runs it, not the kernel
// faulting ~10 MB of fresh pages in each iteration (on this machine that alone doubled times and made them vary).
#include <benchmark/benchmark.h>

#include "apps/drover/heap_tuning.hpp"

namespace drover::bench {

inline int runWithTunedHeap(int argc, char** argv) {
  drover::cli::tuneHeapForSweeps();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace drover::bench
