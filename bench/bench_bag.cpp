// ROS bag reader throughput: messages per second reading a generated bag of 2000 IMU messages (200 Hz) and 100
// Velodyne-style clouds of 30k points (32-byte points, ~1 MB each), uncompressed and lz4, plus the parts: index
// reading alone and PointCloud2 decoding from memory. The bags are written once by
// tests/io/fixtures/write_bags.py (python3-rosbag) into a temporary folder.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/bag_format.hpp"
#include "io/bag_reader.hpp"
#include "io/ros_pointcloud.hpp"

namespace {

namespace fs = std::filesystem;
constexpr int kImu = 2000, kClouds = 100, kPoints = 30000;

class BenchBags {
 public:
  static const BenchBags& get() {
    static const BenchBags instance;
    return instance;
  }
  std::string bag(const std::string& compression) const { return (dir_ / ("bench_" + compression + ".bag")).string(); }
  ~BenchBags() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

 private:
  BenchBags() : dir_(fs::temp_directory_path() / ("drover_bench_bag_" + std::to_string(::getpid()))) {
    fs::create_directories(dir_);
    const fs::path script = fs::path(__FILE__).parent_path().parent_path() / "tests/io/fixtures/write_bags.py";
    const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + dir_.string() + "' --bench " +
                            std::to_string(kImu) + " " + std::to_string(kClouds) + " " + std::to_string(kPoints);
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("cannot write the benchmark bags: " + cmd);
  }
  fs::path dir_;
};

drover::io::DatasetOptions benchOptions() {
  drover::io::DatasetOptions o;
  o.lidar_topic = "/points_raw";
  o.imu_topic = "/imu_raw";
  return o;
}

void BM_ReadBag(benchmark::State& state, const std::string& compression) {
  const std::string path = BenchBags::get().bag(compression);
  std::int64_t messages = 0, points = 0;
  for (auto _ : state) {
    drover::io::BagReader reader(path, benchOptions());
    while (auto m = reader.next()) {
      ++messages;
      if (const auto* scan = std::get_if<drover::LidarScan>(&*m)) points += static_cast<std::int64_t>(scan->points.size());
      benchmark::DoNotOptimize(*m);
    }
  }
  state.counters["msgs/s"] = benchmark::Counter(static_cast<double>(messages), benchmark::Counter::kIsRate);
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * fs::file_size(path)));
}
BENCHMARK_CAPTURE(BM_ReadBag, none, std::string("none"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadBag, lz4, std::string("lz4"))->Unit(benchmark::kMillisecond);

void BM_ReadBagIndex(benchmark::State& state) {
  const std::string path = BenchBags::get().bag("lz4");
  for (auto _ : state) {
    drover::io::bag::BagFile file(path);
    benchmark::DoNotOptimize(file.readIndex());
  }
}
BENCHMARK(BM_ReadBagIndex)->Unit(benchmark::kMicrosecond);

void BM_DecodePointCloud2(benchmark::State& state) {
  drover::io::bag::BagFile file(BenchBags::get().bag("none"));
  const drover::io::bag::BagIndex index = file.readIndex();
  std::uint32_t cloud_conn = 0;
  for (const auto& c : index.connections)
    if (c.topic == "/points_raw") cloud_conn = c.id;
  const auto entry = std::find_if(index.entries.begin(), index.entries.end(),
                                  [&](const auto& e) { return e.conn == cloud_conn; });
  const auto [data, size] = file.messageData(index, *entry);
  const std::vector<std::uint8_t> message(data, data + size);
  for (auto _ : state) benchmark::DoNotOptimize(drover::io::ros::decodePointCloud2(message.data(), message.size()));
  state.counters["points/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * kPoints, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodePointCloud2)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
