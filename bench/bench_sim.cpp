// Simulator throughput on the farm scenario with the default robot (VLP-16 at 10 Hz, 640x480 mono camera at 15 Hz,
// IMU at 200 Hz): a whole dataset written to a temporary folder (reported as simulated seconds per wall second),
// and one lidar sweep, one camera frame and the IMU on their own. Scenario building is outside the timings.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "io/sim_dataset.hpp"
#include "sim/random.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace {

namespace fs = std::filesystem;
namespace sim = drover::sim;
using drover::Time;

constexpr double kSeconds = 5.0;  // simulated per dataset iteration

const sim::Scenario& farm() {
  static const sim::Scenario s = [] {
    sim::ScenarioOptions o;
    o.seed = 1;
    o.duration_s = 60.0;
    return sim::makeScenario("farm", o);
  }();
  return s;
}

// The first kSeconds of the farm course.
const sim::Scenario& farmStart() {
  static const sim::Scenario s = [] {
    sim::ScenarioOptions o;
    o.seed = 1;
    o.duration_s = kSeconds;
    return sim::makeScenario("farm", o);
  }();
  return s;
}

void BM_SimFarmDatasetToFolder(benchmark::State& state) {
  const sim::Scenario& scenario = farmStart();
  const sim::Simulator simulator(scenario, sim::SimulatorConfig::defaults(), 1);
  const fs::path dir = fs::temp_directory_path() / ("drover_bench_sim_" + std::to_string(::getpid()));
  std::size_t frames = 0;
  for (auto _ : state) {
    drover::io::SimWriterOptions o;
    o.overwrite = true;
    drover::io::SimDatasetWriter writer(dir.string(), simulator.datasetDescription(), o);
    simulator.run([&](drover::Measurement&& m) { writer.add(std::move(m)); });
    writer.finish(simulator.groundTruth());
    frames = writer.counts().camera;
  }
  fs::remove_all(dir);
  const double sim_s = drover::toSeconds(scenario.trajectory->endTime() - scenario.trajectory->startTime());
  state.counters["sim_s_per_wall_s"] =
      benchmark::Counter(sim_s * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["frames"] = static_cast<double>(frames);
}
BENCHMARK(BM_SimFarmDatasetToFolder)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_SimLidarSweepVlp16(benchmark::State& state) {
  const sim::Scenario& s = farm();
  const sim::SimulatorConfig c = sim::SimulatorConfig::defaults();
  std::uint64_t k = 0;
  std::size_t points = 0;
  for (auto _ : state) {
    const Time t0 = s.trajectory->startTime() + static_cast<Time>(k % 500) * 100'000'000;
    const drover::LidarScan scan = sim::simulateSweep(s.world, *s.trajectory, c.T_imu_lidar, t0, c.lidar, 1, k++);
    points = scan.points.size();
    benchmark::DoNotOptimize(scan.points.data());
  }
  state.counters["points"] = static_cast<double>(points);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimLidarSweepVlp16)->Unit(benchmark::kMillisecond)->UseRealTime();

// Args: rays per pixel side (sim.camera_pixel_samples; the farm configs ship 2), edge rays per pixel side
// (sim.camera_edge_pixel_samples, 0 = off), texture filter (sim.camera_texture_filter, 0/1).
void BM_SimCameraFrame640x480(benchmark::State& state) {
  const sim::Scenario& s = farm();
  sim::SimulatorConfig c = sim::SimulatorConfig::defaults();
  c.camera.pixel_samples = static_cast<int>(state.range(0));
  c.camera.edge_pixel_samples = static_cast<int>(state.range(1));
  c.camera.texture_filter = state.range(2) != 0;
  const sim::CameraRenderer renderer(c.camera);
  std::uint64_t k = 0;
  for (auto _ : state) {
    const Time t = s.trajectory->startTime() + 5'000'000 + static_cast<Time>(k % 800) * 66'666'667;
    const drover::CameraFrame f = renderer.render(s.world, *s.trajectory, c.T_imu_cam, s.illumination, t, 1, k++);
    benchmark::DoNotOptimize(f.image.data.data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_SimCameraFrame640x480)
    ->ArgNames({"rays", "edge", "filter"})
    ->Args({1, 0, 0})
    ->Args({2, 0, 0})
    ->Args({2, 0, 1})
    ->Args({3, 0, 1})
    ->Args({2, 4, 1})
    ->Args({4, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SimImu60s(benchmark::State& state) {
  const sim::Scenario& s = farm();
  const sim::ImuModelConfig c;
  std::size_t n = 0;
  for (auto _ : state) {
    const auto samples = sim::simulateImu(*s.trajectory, c, 1);
    n = samples.size();
    benchmark::DoNotOptimize(samples.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_SimImu60s)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
