// Speed of the lidar(-inertial) odometry, whole pipeline and per stage (issue 4: >= 10x real time on VLP-16 sweeps,
// >= 3x on 120k-point HDL-64 sweeps, on 2 cores). Inputs are generated in memory once (the simulator's farm course
// with IMU, VLP-16 and HDL-64) or read from ../shared (the 10 real KITTI 00 scans). Counters: real_time_factor =
// data seconds / wall seconds, and the mean milliseconds of each stage per sweep.
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

#include "bench/heap_tuned_main.hpp"
#include "io/config.hpp"
#include "io/dataset.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"
#include "support/shared_data.hpp"

namespace {

using drover::Measurement;
namespace pipeline = drover::pipeline;
namespace sim = drover::sim;

struct Input {
  std::vector<Measurement> stream;
  drover::Calibration calibration;
  pipeline::OdometryConfig config;
  double seconds = 0;  // data span
};

// 20 s of the farm course from its start (garage exit: at rest, then driving), with IMU, no camera.
const Input& farm(const std::string& lidar) {
  static std::map<std::string, Input> cache;
  auto it = cache.find(lidar);
  if (it != cache.end()) return it->second;
  sim::ScenarioOptions so;
  so.duration_s = 20.0;
  static std::map<std::string, sim::Scenario> scenarios;
  const sim::Scenario& scenario = scenarios.emplace(lidar, sim::makeScenario("farm", so)).first->second;
  sim::SimulatorConfig c = sim::SimulatorConfig::defaults();
  c.enable_camera = false;
  c.lidar = sim::LidarModelConfig::forModel(lidar);
  const sim::Simulator simulator(scenario, c, 1);
  Input in;
  simulator.run([&](Measurement&& m) { in.stream.push_back(std::move(m)); });
  in.calibration = simulator.calibration();
  in.config = drover::io::loadOdometryConfig(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml");
  if (lidar == "hdl64") {
    in.config.layout = drover::lidar::ScanLayoutConfig::kittiHdl64();
    in.config.features.columns = 2083;
  }
  in.seconds = so.duration_s;
  return cache.emplace(lidar, std::move(in)).first->second;
}

const Input* kitti00() {
  static const Input in = [] {
    Input r;
    const std::string config = std::string(DROVER_SOURCE_DIR) + "/config/kitti.yaml";
    drover::io::DatasetOptions o = drover::io::loadDatasetOptions(config);
    o.load_images = false;
    o.kitti_max_frames = 10;
    const auto dir = drover::test::sharedData("kitti/sequences/00");
    if (!std::filesystem::exists(dir / "velodyne" / "000009.bin")) return r;
    auto reader = drover::io::openDataset(dir.string(), "kitti", o);
    while (auto m = reader->next()) r.stream.push_back(std::move(*m));
    r.calibration = reader->calibration();
    r.config = drover::io::loadOdometryConfig(config);
    r.seconds = 10 * 0.1037;
    return r;
  }();
  return in.stream.empty() ? nullptr : &in;
}

void runPipeline(benchmark::State& state, const Input& in) {
  pipeline::StageTimes sum;
  std::size_t sweeps = 0, points = 0;
  for (auto _ : state) {
    pipeline::LidarOdometry odometry(in.config, in.calibration);
    std::vector<pipeline::ScanOutcome> all;
    for (const Measurement& m : in.stream)
      for (pipeline::ScanOutcome& o : odometry.process(m)) all.push_back(std::move(o));
    for (pipeline::ScanOutcome& o : odometry.finish()) all.push_back(std::move(o));
    for (const pipeline::ScanOutcome& o : all) {
      sum.preprocess += o.ms.preprocess;
      sum.deskew += o.ms.deskew;
      sum.features += o.ms.features;
      sum.map += o.ms.map;
      sum.match += o.ms.match;
      sum.smoother += o.ms.smoother;
      sum.loop += o.ms.loop;
      sum.total += o.ms.total;
      points += o.points;
    }
    sweeps += all.size();
  }
  const double n = static_cast<double>(std::max<std::size_t>(sweeps, 1));
  state.counters["real_time_factor"] =
      benchmark::Counter(in.seconds * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["points_per_sweep"] = static_cast<double>(points) / n;
  state.counters["ms_preprocess"] = sum.preprocess / n;
  state.counters["ms_deskew"] = sum.deskew / n;
  state.counters["ms_features"] = sum.features / n;
  state.counters["ms_map"] = sum.map / n;
  state.counters["ms_match"] = sum.match / n;
  state.counters["ms_smoother"] = sum.smoother / n;
  state.counters["ms_loop"] = sum.loop / n;  // loop closure (on in the configs; no revisit on these short runs)
  state.counters["ms_per_sweep"] = sum.total / n;
}

void BM_LisFarmVlp16WithImu(benchmark::State& state) { runPipeline(state, farm("vlp16")); }
BENCHMARK(BM_LisFarmVlp16WithImu)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(2);

void BM_LisFarmHdl64WithImu(benchmark::State& state) { runPipeline(state, farm("hdl64")); }
BENCHMARK(BM_LisFarmHdl64WithImu)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_LioKitti00LidarOnly(benchmark::State& state) {
  const Input* in = kitti00();
  if (!in) {
    state.SkipWithError("../shared/data/kitti/sequences/00 not found");
    return;
  }
  runPipeline(state, *in);
}
BENCHMARK(BM_LioKitti00LidarOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace

// As `drover run` does (apps/drover/heap_tuning.hpp).
int main(int argc, char** argv) { return drover::bench::runWithTunedHeap(argc, argv); }
