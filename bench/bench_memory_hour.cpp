// Memory of an hour-long live run: the farm course driven lap after lap (6 laps of ~650 s = ~65 min of data) through
// pipeline::System (LIS + loop closure in their threads), with drover run --realtime's records (the IMU-rate odometry
// streamed to a TUM file, the per-sweep lines to sweeps.jsonl, bounded timing statistics). The simulator feeds the
// system directly, one lap at a time (a 29 GB dataset folder is not needed), each lap's stamps after the previous
// lap's, so the simulator's own memory is the same every lap. The System is fed as fast as it keeps up (a sweep goes
// in once the one before it is processed), not at sensor rate: memory is the question, not latency.
//
// After every lap it prints the process's resident memory (VmRSS) and peak (VmHWM), the keyframes and the bytes of
// their feature clouds (the LIS's map and the loop thread's store), and at the end the ratio of the hour's peak to
// the first lap's (the 10-minute course), overall and without the keyframe clouds. Also malloc's own account
// (mallinfo2, all arenas): the bytes in blocks in use and the free bytes it keeps, to tell growth from fragmentation.
// MODE replay drives the same laps through the deterministic replay (LidarOdometry with its loop closure in line,
// as drover run): the same numbers, reproducible, plus each lap's loop-closure counts (verified, accepted, refused
// by the drift budget, refused by the pose graph) to follow the loop closure over hours.
// LOOP_HZ (live) is the loop thread's rate [Hz of wall time]; the System is fed faster than real time here, so a
// rate of the feeding speed-up (~5) makes corrections land as late in data time as 1 Hz on a robot.
// MODE delayed is the live loop thread made deterministic: the LIS hands its keyframes out as in the System, a
// LoopWorker searches them in a batch every 1 / LOOP_HZ seconds of *data* time, and the newest correction is applied
// before the next sweep, as late as the loop thread would make it, reproducibly.
// The ground truth of every lap (10 Hz, T_world_imu) goes to OUT_DIR/bench_memory_truth.tum, for drover eval ape
// against bench_memory_imu_rate.tum.
//   build/bench/bench_memory_hour [LAPS=6] [SEED=1] [OUT_DIR=/tmp] [MODE=live|replay|delayed] [LOOP_HZ=1] [CONFIG]
//                                 [TRIM_S=30] [CAMERA_DIR]
// CONFIG: a platform file instead of config/farm_sim.yaml (to try a setting over the hour); TRIM_S: the period of
// the heap trim [s of data time] (cli::HeapTrimmer's default is drover's). CAMERA_DIR (live only): the full system,
// drover preset, its VIS fed the frames of that simulated dataset of the same course and seed every lap
// (bench/memory_hour_camera.hpp); the VIS's estimate goes to OUT_DIR/bench_memory_vis.tum.
#include <fmt/format.h>
#include <malloc.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <numbers>
#include <string>

#include "apps/drover/heap_tuning.hpp"
#include "apps/drover/run_preset.hpp"
#include "apps/drover/run_record.hpp"
#include "apps/drover/run_vis.hpp"
#include "bench/memory_hour_camera.hpp"
#include "bench/memory_hour_runners.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/system.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace {

using namespace drover;
using bench::DelayedRunner;
using bench::Lap;
using bench::LiveRunner;
using bench::ReplayRunner;
using bench::Runner;

// [kB] a field of /proc/self/status ("VmRSS", "VmHWM").
long statusKb(const std::string& field) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stol(line.substr(field.size() + 1));
  return -1;
}

// The platform file drover run uses for the farm course, unless another is given.
pipeline::OdometryConfig farmConfig(const std::string& path) {
  return io::loadOdometryConfig(path.empty() ? std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml" : path);
}

// Every verified loop (replay and delayed modes), one line each, to follow the loop closure lap by lap.
void writeLoopEvents(const pipeline::LoopClosure& loops, const std::string& path) {
  std::ofstream out(path);
  // The measured relative pose (query in the candidate's lidar frame: x, y, z [m], yaw [deg]) so that a loop can be
  // judged against the ground truth at t_candidate_s and t_query_s.
  out << "t_query_s,t_candidate_s,query,candidate,source,accepted,implied_drift_m,drift_budget_m,implied_rotation_deg,"
         "rotation_budget_deg,correction_m,graph_iterations,x_m,y_m,z_m,yaw_deg,reason\n";
  for (const pipeline::LoopEvent& e : loops.events()) {
    const Eigen::Isometry3d& T = e.verification.T_candidate_query;
    const double yaw = std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180 / std::numbers::pi;
    out << fmt::format("{:.2f},{:.2f},{},{},{},{},{:.3f},{:.3f},{:.2f},{:.2f},{:.3f},{},{:.3f},{:.3f},{:.3f},{:.2f},"
                       "\"{}\"\n",
                       toSeconds(e.t_query), toSeconds(e.t_candidate), e.query, e.candidate, e.source,
                       e.verification.accepted ? 1 : 0, e.implied_drift, e.drift_budget,
                       e.implied_rotation * 180 / std::numbers::pi, e.rotation_budget * 180 / std::numbers::pi,
                       e.correction, e.graph_iterations, T.translation().x(), T.translation().y(),
                       T.translation().z(), yaw, e.verification.reason);
  }
}

// Every keyframe as the hour ended (replay and delayed modes): to see which places kept their clouds.
void writeKeyframes(const lidar::LocalMap& map, const std::string& path) {
  std::ofstream out(path);
  out << "index,t_s,x_m,y_m,z_m,retired\n";
  for (std::size_t i = 0; i < map.size(); ++i) {
    const lidar::Keyframe& k = map.keyframe(i);
    const Eigen::Vector3d p = k.T_world_lidar.translation();
    out << fmt::format("{},{:.2f},{:.3f},{:.3f},{:.3f},{}\n", i, toSeconds(k.t), p.x(), p.y(), p.z(),
                       k.retired ? 1 : 0);
  }
}

// Resident memory sampled after every sweep: where in the lap it was highest, and with DROVER_HWM_LOG every sweep
// that raised the process's high-water mark by 1 MB or more.
class PeakWatch {
 public:
  void startLap() { lap_max_kb_ = 0, lap_max_t_ = 0; }
  void afterSweep(Time t) {
    const long rss = statusKb("VmRSS");
    if (log_) {
      const long hwm = statusKb("VmHWM");
      if (hwm >= last_hwm_ + 1024)
        std::printf("    hwm %.1f s: %.1f MB (resident after it %.1f MB)\n", toSeconds(t), hwm / 1024.0, rss / 1024.0);
      last_hwm_ = std::max(last_hwm_, hwm);
    }
    if (rss > lap_max_kb_) lap_max_kb_ = rss, lap_max_t_ = t;
  }
  void printLap(int lap) const {
    std::printf("  (lap %d: resident memory sampled after every sweep highest at %.1f s: %.1f MB)\n", lap,
                toSeconds(lap_max_t_), lap_max_kb_ / 1024.0);
  }

 private:
  bool log_ = std::getenv("DROVER_HWM_LOG") != nullptr;
  long last_hwm_ = 0, lap_max_kb_ = 0;  // [kB]
  Time lap_max_t_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  cli::tuneHeapForSweeps();  // the heap as drover run and drover_ros have it, returned every 30 s (HeapTrimmer)
  const int laps = argc > 1 ? std::stoi(argv[1]) : 6;
  const unsigned seed = argc > 2 ? static_cast<unsigned>(std::stoul(argv[2])) : 1;
  const std::string out_dir = argc > 3 ? argv[3] : "/tmp";
  const std::string mode = argc > 4 ? argv[4] : "live";
  const double loop_hz = argc > 5 ? std::stod(argv[5]) : 1.0;
  const std::string config_path = argc > 6 ? argv[6] : "";
  cli::HeapTrimmer heap(argc > 7 ? fromSeconds(std::stod(argv[7])) : cli::HeapTrimmer::kDefaultPeriod);
  const std::string camera_dir = argc > 8 ? argv[8] : "";
  if (mode != "live" && mode != "replay" && mode != "delayed") {
    std::fprintf(stderr, "MODE must be live, replay or delayed, not '%s'\n", mode.c_str());
    return 2;
  }
  if (!camera_dir.empty() && mode != "live") {
    std::fprintf(stderr, "CAMERA_DIR needs MODE live (the System's VIS thread)\n");
    return 2;
  }
  std::unique_ptr<bench::CameraReplay> camera;
  if (!camera_dir.empty()) camera = std::make_unique<bench::CameraReplay>(camera_dir);
  sim::ScenarioOptions so;
  so.seed = seed;
  const sim::Scenario scenario = sim::makeScenario("farm", so);
  sim::SimulatorConfig sc = sim::SimulatorConfig::defaults();
  sc.enable_camera = false;
  // One IMU period after the lap's last sample: the next lap's first (at rest, at the same pose).
  const Time lap_span = sim::Simulator(scenario, sc, seed).groundTruth().back().t + 5'000'000;
  const Calibration calibration = camera ? camera->calibration() : sim::Simulator(scenario, sc, seed).calibration();

  std::unique_ptr<Runner> runner;
  if (camera) {
    // The full system as drover run --preset drover runs it: the preset over the platform file.
    const std::string platform = config_path.empty() ? std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml"
                                                     : config_path;
    const cli::MethodChoice drover{cli::Preset::kDrover, {}};
    pipeline::OdometryConfig odometry = farmConfig(platform);
    drover.apply(odometry);
    const cli::VisSetup vis = cli::loadVisSetup(platform, drover);
    std::printf("camera: frames of %s every lap, the VIS with %s (drover preset)\n", camera_dir.c_str(),
                vis.detector_name.c_str());
    runner = std::make_unique<LiveRunner>(odometry, calibration, loop_hz, &vis, out_dir + "/bench_memory_vis.tum");
  } else if (mode == "live") {
    runner = std::make_unique<LiveRunner>(farmConfig(config_path), calibration, loop_hz);
  } else if (mode == "delayed") {
    runner = std::make_unique<DelayedRunner>(farmConfig(config_path), calibration, 1.0 / loop_hz);
  } else {
    runner = std::make_unique<ReplayRunner>(farmConfig(config_path), calibration);
  }
  // Streamed as it comes: held in memory, an hour's truth at 10 Hz (5 MB) would count in the peak it measures.
  io::TumStream truth(out_dir + "/bench_memory_truth.tum");
  runner->record.log.streamTo(out_dir + "/bench_memory_sweeps.jsonl");
  runner->record.imu_rate =
      std::make_shared<cli::ImuRateFile>(out_dir + "/bench_memory_imu_rate.tum", Eigen::Isometry3d::Identity());

  std::vector<Lap> rows;
  PeakWatch peaks;
  const auto wall0 = std::chrono::steady_clock::now();
  std::printf("%s: lap  data_s  wall_s  sweeps  keyframes  retired  loops  dropped  RSS_MB  peak_MB  kf_LIS_MB  "
              "kf_loop_MB  cache_MB  SC_MB  | verified  accepted  over_budget  graph_refused  graph_ms  iterations  "
              "max_rot_deg  graph_nodes  heap_used_MB  heap_free_MB\n",
              mode.c_str());
  for (int lap = 0; lap < laps; ++lap) {
    const Time offset = lap * lap_span;
    // Each lap its own noise (seed + lap); the same world and path: the robot drives the same course again.
    const sim::Simulator simulator(scenario, sc, seed + static_cast<unsigned>(lap) * 1000);
    peaks.startLap();
    if (camera) camera->startLap(offset);
    const Trajectory lap_truth = simulator.groundTruth();
    for (std::size_t i = 0; i < lap_truth.size(); i += 20)
      truth.add({lap_truth[i].t + offset, lap_truth[i].T_world_body});
    truth.flush();
    simulator.run([&](Measurement&& m) {
      if (auto* imu = std::get_if<ImuSample>(&m)) {
        imu->t += offset;
      } else if (auto* scan = std::get_if<LidarScan>(&m)) {
        scan->t += offset;
        scan->t_end += offset;
      }
      const Time t = measurementTime(m);
      if (camera) camera->pushUpTo(t, [&](CameraFrame&& f) { runner->push(Measurement(std::move(f))); });
      const bool sweep = std::holds_alternative<LidarScan>(m);
      heap.tick(t);
      runner->push(std::move(m));
      if (sweep) peaks.afterSweep(t);
    });
    peaks.printLap(lap + 1);
    Lap row;
    row.lap = lap + 1;
    row.data_s = toSeconds((lap + 1) * lap_span);
    row.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    runner->fill(row);
    row.rss_kb = statusKb("VmRSS");
    row.peak_kb = statusKb("VmHWM");
    const struct mallinfo2 heap = mallinfo2();
    row.heap_used = heap.uordblks + heap.hblkhd;
    row.heap_free = heap.fordblks;
    rows.push_back(row);
    const pipeline::LoopStats& ls = row.loop_stats;
    std::printf("%3d  %6.0f  %6.0f  %6zu  %9zu  %7zu  %5zu  %7zu  %6.1f  %7.1f  %9.1f  %10.1f  %8.1f  %5.1f  | %8zu  "
                "%8zu  %11zu  %13zu  %8.0f  %10.1f  %11.1f  %11zu  %12.1f  %12.1f\n",
                row.lap, row.data_s, row.wall_s, row.sweeps, row.keyframes, row.retired, row.loops, row.dropped,
                row.rss_kb / 1024.0, row.peak_kb / 1024.0, row.kf_lis / 1048576.0, row.kf_loop / 1048576.0,
                row.cache / 1048576.0, row.descriptors / 1048576.0, ls.verified, ls.accepted, ls.over_drift_budget,
                row.graph_refusals, ls.graph_ms, row.graph_iterations, row.max_rotation * 180 / std::numbers::pi,
                row.graph_nodes, row.heap_used / 1048576.0, row.heap_free / 1048576.0);
    if (camera)
      std::printf("  (lap %d: the VIS took %zu frames in all, %zu dropped from its queue, %zu with an estimate)\n",
                  row.lap, row.frames, row.frames_dropped, row.vis_estimates);
    std::fflush(stdout);
  }
  // DROVER_EXIT_AT_END: leave without freeing anything, so that heaptrack reports what the hour holds at its end
  // as "leaked", call site by call site (run 1 lap and 3, compare).
  if (std::getenv("DROVER_EXIT_AT_END")) {
    std::fflush(stdout);
    std::_Exit(0);
  }
  runner->finish();
  truth.close();
  if (const pipeline::LoopClosure* loops = runner->loops())
    writeLoopEvents(*loops, out_dir + "/bench_memory_loops.csv");
  if (const lidar::LocalMap* map = runner->keyframes()) writeKeyframes(*map, out_dir + "/bench_memory_keyframes.csv");
  const Lap& first = rows.front();
  const Lap& last = rows.back();
  const auto mb = [](double kb) { return kb / 1024.0; };
  const double kf_first = (first.kf_lis + first.kf_loop) / 1024.0, kf_last = (last.kf_lis + last.kf_loop) / 1024.0;
  std::printf("\npeak after lap 1 (the 10-minute course): %.1f MB, of which keyframe clouds %.1f MB\n",
              mb(first.peak_kb), mb(kf_first));
  std::printf("peak after lap %d (%.0f min of data): %.1f MB, of which keyframe clouds %.1f MB\n", last.lap,
              last.data_s / 60, mb(last.peak_kb), mb(kf_last));
  std::printf("ratio of peaks: %.2f overall, %.2f without the keyframe clouds\n",
              static_cast<double>(last.peak_kb) / first.peak_kb, (last.peak_kb - kf_last) / (first.peak_kb - kf_first));
  std::printf("records streamed: %zu sweep lines, %zu IMU-rate poses; the heap trimmed %lld times (%.0f ms)\n",
              runner->record.log.lines(), runner->record.imu_rate->copyTo(out_dir + "/bench_memory_imu_rate.tum").poses,
              static_cast<long long>(heap.trims()), heap.trimSeconds() * 1e3);
  return 0;
}
