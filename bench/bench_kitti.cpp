// KITTI reading throughput on the 10 shared frames of sequence 00 (files in the page cache after the first
// iteration, so this measures parsing and copying, not the disk). MB/s = bytes of .bin (or .png) per second.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/kitti_common.hpp"
#include "io/kitti_odometry.hpp"

namespace {

namespace fs = std::filesystem;

const fs::path kSequence = fs::path(DROVER_SHARED_DIR) / "data" / "kitti" / "sequences" / "00";

std::vector<std::string> sharedFiles(const char* folder, const char* ext) {
  std::vector<std::string> files;
  for (int i = 0; i < 10; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.%s", i, ext);
    const fs::path p = kSequence / folder / name;
    if (fs::exists(p)) files.push_back(p.string());
  }
  return files;
}

bool skipWithoutData(benchmark::State& state, const std::vector<std::string>& files) {
  if (files.size() == 10) return false;
  const std::string msg = "shared data not found: " + kSequence.string() + " (needs ../shared)";
  state.SkipWithError(msg.c_str());
  return true;
}

std::int64_t totalBytes(const std::vector<std::string>& files) {
  std::int64_t n = 0;
  for (const auto& f : files) n += static_cast<std::int64_t>(fs::file_size(f));
  return n;
}

// Baseline: the bytes alone, read into a buffer (what any reader must at least pay).
void BM_KittiBinFileReadOnly(benchmark::State& state) {
  const auto files = sharedFiles("velodyne", "bin");
  if (skipWithoutData(state, files)) return;
  std::vector<char> buf;
  for (auto _ : state) {
    for (const auto& f : files) {
      buf.resize(fs::file_size(f));
      std::ifstream(f, std::ios::binary).read(buf.data(), static_cast<std::streamsize>(buf.size()));
      benchmark::DoNotOptimize(buf.data());
    }
  }
  state.SetBytesProcessed(state.iterations() * totalBytes(files));
}
BENCHMARK(BM_KittiBinFileReadOnly)->Unit(benchmark::kMillisecond);

// readKittiBin: read + finiteness check + conversion to LidarScan.
void BM_KittiBinToLidarScan(benchmark::State& state) {
  const auto files = sharedFiles("velodyne", "bin");
  if (skipWithoutData(state, files)) return;
  std::int64_t points = 0;
  for (auto _ : state) {
    for (const auto& f : files) {
      const drover::LidarScan scan = drover::io::readKittiBin(f, 0, 0);
      points += static_cast<std::int64_t>(scan.points.size());
      benchmark::DoNotOptimize(scan.points.data());
    }
  }
  state.SetBytesProcessed(state.iterations() * totalBytes(files));
  state.SetItemsProcessed(points);
}
BENCHMARK(BM_KittiBinToLidarScan)->Unit(benchmark::kMillisecond);

// The whole reader, scans only (times/calib/poses indexing excluded: it happens once per sequence).
void BM_KittiOdometryReaderScans(benchmark::State& state) {
  const auto files = sharedFiles("velodyne", "bin");
  if (skipWithoutData(state, files)) return;
  drover::io::DatasetOptions options;
  options.load_images = false;
  for (auto _ : state) {
    state.PauseTiming();
    drover::io::KittiOdometryReader reader(kSequence.string(), options);
    state.ResumeTiming();
    for (int i = 0; i < 10; ++i) benchmark::DoNotOptimize(reader.next());
  }
  state.SetBytesProcessed(state.iterations() * totalBytes(files));
}
BENCHMARK(BM_KittiOdometryReaderScans)->Unit(benchmark::kMillisecond);

// PNG decode of the colour images (for scale: images cost far more per byte than scans).
void BM_KittiPngDecode(benchmark::State& state) {
  const auto files = sharedFiles("image_2", "png");
  if (skipWithoutData(state, files)) return;
  for (auto _ : state)
    for (const auto& f : files) benchmark::DoNotOptimize(drover::io::readImageFile(f).data.data());
  state.SetBytesProcessed(state.iterations() * totalBytes(files));
}
BENCHMARK(BM_KittiPngDecode)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
