// Memory of an hour-long live run: the farm course driven lap after lap (6 laps of ~650 s = ~65 min of data) through
// pipeline::System (LIS + loop closure in their threads), with drover run --realtime's records (the IMU-rate odometry
// streamed to a TUM file, the per-sweep lines to sweeps.jsonl, bounded timing statistics). The simulator feeds the
// system directly, one lap at a time (a 29 GB dataset folder is not needed), each lap's stamps after the previous
// lap's, so the simulator's own memory is the same every lap. The System is fed as fast as it keeps up (a sweep goes
// in once the one before it is processed), not at sensor rate: memory is the question, not latency.
//
// After every lap it prints the process's resident memory (VmRSS) and peak (VmHWM), the keyframes and the bytes of
// their feature clouds (the LIS's map and the loop thread's store), and at the end the ratio of the hour's peak to
// the first lap's (the 10-minute course), overall and without the keyframe clouds.
//   build/bench/bench_memory_hour [LAPS=6] [SEED=1] [OUT_DIR=/tmp]
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "apps/drover/run_record.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "pipeline/system.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace {

using namespace drover;

// [kB] a field of /proc/self/status ("VmRSS", "VmHWM").
long statusKb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  return -1;
}

pipeline::OdometryConfig farmConfig() {  // the platform file drover run uses for the farm course
  return io::loadOdometryConfig(std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml");
}

struct Lap {
  int lap = 0;
  double data_s = 0, wall_s = 0;
  long rss_kb = 0, peak_kb = 0;
  std::size_t sweeps = 0, keyframes = 0, dropped = 0, loops = 0;
  pipeline::System::KeyframeMemory kf;
};

}  // namespace

int main(int argc, char** argv) {
  const int laps = argc > 1 ? std::stoi(argv[1]) : 6;
  const unsigned seed = argc > 2 ? static_cast<unsigned>(std::stoul(argv[2])) : 1;
  const std::string out_dir = argc > 3 ? argv[3] : "/tmp";
  sim::ScenarioOptions so;
  so.seed = seed;
  const sim::Scenario scenario = sim::makeScenario("farm", so);
  sim::SimulatorConfig sc = sim::SimulatorConfig::defaults();
  sc.enable_camera = false;
  // One IMU period after the lap's last sample: the next lap's first (at rest, at the same pose).
  const Time lap_span = sim::Simulator(scenario, sc, seed).groundTruth().back().t + 5'000'000;

  std::atomic<std::size_t> processed{0};
  cli::RunRecord record;
  record.log.streamTo(out_dir + "/bench_memory_sweeps.jsonl");
  record.imu_rate = std::make_shared<cli::ImuRateFile>(out_dir + "/bench_memory_imu_rate.tum",
                                                      Eigen::Isometry3d::Identity());
  std::mutex record_mutex;
  pipeline::SystemCallbacks cb;
  cb.imu_odometry = [&](const pipeline::ImuOdometry& o) { record.imu_rate->add(o.t, o.T_world_imu); };
  cb.sweep = [&](const pipeline::ScanOutcome& s) {
    {
      std::lock_guard<std::mutex> lock(record_mutex);
      record.add(s);
    }
    ++processed;
  };
  pipeline::SystemConfig config;
  config.odometry = farmConfig();
  config.live.sweep_queue = 4;
  pipeline::System system(config, sim::Simulator(scenario, sc, seed).calibration(), cb);

  std::vector<Lap> rows;
  const auto wall0 = std::chrono::steady_clock::now();
  std::size_t pushed = 0;
  std::printf("lap  data_s  wall_s  sweeps  keyframes  loops  dropped  RSS_MB  peak_MB  kf_LIS_MB  kf_loop_MB\n");
  for (int lap = 0; lap < laps; ++lap) {
    const Time offset = lap * lap_span;
    // Each lap its own noise (seed + lap); the same world and path: the robot drives the same course again.
    const sim::Simulator simulator(scenario, sc, seed + static_cast<unsigned>(lap) * 1000);
    simulator.run([&](Measurement&& m) {
      if (auto* imu = std::get_if<ImuSample>(&m)) {
        imu->t += offset;
        system.pushImu(*imu);
      } else if (auto* scan = std::get_if<LidarScan>(&m)) {
        scan->t += offset;
        scan->t_end += offset;
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
        while (processed.load() + system.stats().sweeps_dropped + 1 < pushed &&
               std::chrono::steady_clock::now() < deadline)
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        ++pushed;
        system.pushSweep(std::move(*scan));
      }
    });
    Lap row;
    row.lap = lap + 1;
    row.data_s = toSeconds((lap + 1) * lap_span);
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    row.rss_kb = statusKb("VmRSS");
    row.peak_kb = statusKb("VmHWM");
    row.sweeps = processed.load();
    row.dropped = system.stats().sweeps_dropped;
    row.loops = system.stats().loops_applied;
    row.kf = system.keyframeMemory();
    system.inspect([&](const pipeline::LidarOdometry& lis, const pipeline::LoopClosure*) {
      row.keyframes = lis.stats().keyframes;
    });
    rows.push_back(row);
    std::printf("%3d  %6.0f  %6.0f  %6zu  %9zu  %5zu  %7zu  %6.1f  %7.1f  %9.1f  %10.1f\n", row.lap, row.data_s,
                row.wall_s, row.sweeps, row.keyframes, row.loops, row.dropped, row.rss_kb / 1024.0,
                row.peak_kb / 1024.0, row.kf.lis / 1048576.0, row.kf.loop / 1048576.0);
    std::fflush(stdout);
  }
  system.shutdown();
  const Lap& first = rows.front();
  const Lap& last = rows.back();
  const auto mb = [](double kb) { return kb / 1024.0; };
  const double kf_first = (first.kf.lis + first.kf.loop) / 1024.0, kf_last = (last.kf.lis + last.kf.loop) / 1024.0;
  std::printf("\npeak after lap 1 (the 10-minute course): %.1f MB, of which keyframe clouds %.1f MB\n",
              mb(first.peak_kb), mb(kf_first));
  std::printf("peak after lap %d (%.0f min of data): %.1f MB, of which keyframe clouds %.1f MB\n", last.lap,
              last.data_s / 60, mb(last.peak_kb), mb(kf_last));
  std::printf("ratio of peaks: %.2f overall, %.2f without the keyframe clouds\n",
              static_cast<double>(last.peak_kb) / first.peak_kb, (last.peak_kb - kf_last) / (first.peak_kb - kf_first));
  std::printf("records streamed: %zu sweep lines, %zu IMU-rate poses\n", record.log.lines(),
              record.imu_rate->copyTo(out_dir + "/bench_memory_imu_rate.tum").poses);
  return 0;
}
