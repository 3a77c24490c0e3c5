// Scan Context costs (issue 5): the descriptor of a real 124k-point KITTI scan, and the full shift search against
// the paper's prior-narrowed one (dh = 3 of 60 sectors) on the real revisit pair of sequence 08.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>
#include <string>

#include "io/kitti_common.hpp"
#include "loop/scan_context.hpp"
#include "support/shared_data.hpp"

namespace {

namespace loop = drover::loop;

const drover::lidar::PointCloud* cloud(const char* name) {
  static std::map<std::string, drover::lidar::PointCloud> cache;
  const auto path = drover::test::sharedData(std::string("kitti/revisit_08/") + name);
  if (!std::filesystem::exists(path)) return nullptr;
  auto [it, inserted] = cache.try_emplace(name);
  if (inserted)
    for (const auto& p : drover::io::readKittiBin(path.string(), 0, 0).points) it->second.emplace_back(p.x, p.y, p.z);
  return &it->second;
}

void BM_ScanContextDescriptorKitti(benchmark::State& state) {
  const auto* c = cloud("000720.bin");
  if (!c) return state.SkipWithError("../shared/data/kitti/revisit_08 not found");
  for (auto _ : state) benchmark::DoNotOptimize(loop::makeScanContext(*c, {}).image.data());
  state.counters["points"] = static_cast<double>(c->size());
}
BENCHMARK(BM_ScanContextDescriptorKitti)->Unit(benchmark::kMillisecond);

// The query side of the lateral augmentation: 9 descriptors (3 x 3 virtual positions, 2 m apart).
void BM_AugmentedScanContextKitti(benchmark::State& state) {
  const auto* c = cloud("001500.bin");
  if (!c) return state.SkipWithError("../shared/data/kitti/revisit_08 not found");
  for (auto _ : state) benchmark::DoNotOptimize(loop::makeAugmentedScanContext(*c, {}).descriptors.data());
}
BENCHMARK(BM_AugmentedScanContextKitti)->Unit(benchmark::kMillisecond);

void shiftSearch(benchmark::State& state, bool narrowed) {
  const auto *a = cloud("000720.bin"), *b = cloud("001500.bin");
  if (!a || !b) return state.SkipWithError("../shared/data/kitti/revisit_08 not found");
  loop::ScanContextConfig cfg;
  cfg.threshold = 0.3;  // the pair's distance is 0.22: keep the narrowed search from falling back
  const loop::ScanContext sa = loop::makeScanContext(*a, cfg), sb = loop::makeScanContext(*b, cfg);
  const double prior = loop::fullShiftSearch(sa, sb).yaw + 0.05;
  for (auto _ : state) {
    const loop::ShiftMatch m = narrowed ? loop::narrowedShiftSearch(sa, sb, prior, cfg) : loop::fullShiftSearch(sa, sb);
    benchmark::DoNotOptimize(m.shift);
  }
}
void BM_ShiftSearchFull(benchmark::State& state) { shiftSearch(state, false); }
void BM_ShiftSearchPriorNarrowed(benchmark::State& state) { shiftSearch(state, true); }
BENCHMARK(BM_ShiftSearchFull)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ShiftSearchPriorNarrowed)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
