// drover sim: generate a simulated dataset (lidar, camera, IMU, ground truth) that `--format sim` reads back, or
// with --format bag a ROS1 bag that `--format bag` reads. The simulation is in src/sim, the folder format in
// src/io/sim_dataset.hpp, the bag's topics in src/io/sim_bag.hpp; this file parses and reports progress.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "io/error.hpp"
#include "io/euroc_writer.hpp"
#include "io/sim_bag.hpp"
#include "io/sim_dataset.hpp"
#include "io/trajectory_io.hpp"
#include "io/user_values.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace drover::cli {
namespace {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string joined(const std::vector<std::string>& names);

struct SimOptions {
  std::string scenario, out, format = "folder", config, lidar, kitti_poses, kitti_times;
  std::uint64_t seed = 1;
  double duration = 0;     // [s], 0 = the scenario's natural length
  std::optional<double> camera_rate;  // [Hz]; unset: the config's, else 15
  bool no_camera = false, force = false, quiet = false;
  std::vector<sim::SensorFault> faults;  // --fault, windows relative to the trajectory's start
};

// --fault KIND@START+DURATION, seconds from the trajectory's start: "camera-blackout@60+10".
sim::SensorFault parseFault(const std::string& text) {
  const io::ValueSource source = io::ValueSource::option("--fault");
  const std::size_t at = text.find('@'), plus = text.find('+', at == std::string::npos ? 0 : at);
  if (at == std::string::npos || plus == std::string::npos)
    io::failValue(source, "expected KIND@START+DURATION (seconds), e.g. camera-blackout@60+10, got " + io::echo(text));
  const std::optional<sim::FaultKind> kind = sim::faultKind(text.substr(0, at));
  if (!kind)
    io::failValue(source, "unknown fault " + io::echo(text.substr(0, at)) + " (expected one of: " +
                              joined(sim::faultNames()) + ")");
  sim::SensorFault f;
  f.kind = *kind;
  f.start = io::parseSecondsValue(text.substr(at + 1, plus - at - 1), io::between(0, io::kMaxSimDurationS, "s"), source);
  f.end = f.start + io::parseSecondsValue(text.substr(plus + 1), io::Range{0, 600, true, false, "s"}, source);
  return f;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// ../shared/data: $DROVER_SHARED_DIR/data, then ../shared/data from the current folder, then beside the sources.
std::optional<fs::path> sharedData() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("DROVER_SHARED_DIR")) candidates.push_back(fs::path(env) / "data");
  candidates.push_back(fs::path("..") / "shared" / "data");
  candidates.push_back(fs::path(DROVER_SOURCE_DIR) / ".." / "shared" / "data");
  for (const fs::path& c : candidates)
    if (fs::is_directory(c)) return c;
  return std::nullopt;
}

// KITTI 05 ground truth (camera-0 poses with times) for kitti05-replay.
Trajectory loadKitti05(const SimOptions& o) {
  const std::optional<fs::path> data = sharedData();
  std::string poses = o.kitti_poses, times = o.kitti_times;
  if (poses.empty() && data) poses = (*data / "kitti" / "poses" / "05.txt").string();
  if (times.empty() && data) times = (*data / "kitti" / "sequences" / "05" / "times.txt").string();
  if (poses.empty() || times.empty())
    throw std::invalid_argument(
        "kitti05-replay needs KITTI 05 poses and times: ../shared/data not found; pass --kitti-poses and "
        "--kitti-times");
  return io::readKitti(poses, times);
}

sim::SimulatorConfig simulatorConfig(const SimOptions& o) {
  io::SimConfigSettings s;
  if (!o.config.empty()) s = io::loadSimConfigSettings(o.config);
  sim::SimulatorConfig c = s.rig == "euroc" ? sim::SimulatorConfig::eurocRig() : sim::SimulatorConfig::defaults();
  c.lidar = sim::LidarModelConfig::forModel(!o.lidar.empty() ? o.lidar : s.lidar_model.value_or("vlp16"));
  if (s.lidar_rate_hz) c.lidar.rate_hz = *s.lidar_rate_hz;
  if (s.lidar_columns) c.lidar.columns = *s.lidar_columns;
  if (s.camera_rate_hz) c.camera.rate_hz = *s.camera_rate_hz;
  if (o.camera_rate) c.camera.rate_hz = *o.camera_rate;
  if (s.camera_color) c.camera.color = *s.camera_color;
  if (s.camera_pixel_samples) c.camera.pixel_samples = *s.camera_pixel_samples;
  if (s.camera_texture_filter) c.camera.texture_filter = *s.camera_texture_filter;
  if (s.camera_edge_pixel_samples) c.camera.edge_pixel_samples = *s.camera_edge_pixel_samples;
  if (s.imu_rate_hz) c.imu.rate_hz = *s.imu_rate_hz;
  if (s.ground_truth_rate_hz) c.ground_truth_rate_hz = *s.ground_truth_rate_hz;
  if (s.lidar_time_offset_s) c.lidar_time_offset = fromSeconds(*s.lidar_time_offset_s);
  if (s.camera_time_offset_s) c.camera_time_offset = fromSeconds(*s.camera_time_offset_s);
  if (s.noise && !*s.noise) c.lidar.noise = c.camera.noise = c.imu.noise = false;
  c.enable_camera = !o.no_camera;
  if (o.format == "euroc") c.enable_lidar = false;  // EuRoC's layout has no lidar
  if (!o.lidar.empty() && !c.enable_lidar)
    throw std::invalid_argument("--lidar: this rig or format has no lidar (EuRoC's camera + IMU)");
  c.faults = o.faults;
  if (std::string e = c.validate(); !e.empty()) throw std::invalid_argument("simulator settings: " + e);
  return c;
}

void checkOptions(const SimOptions& o) {
  const std::vector<std::string> names = sim::scenarioNames();
  if (std::find(names.begin(), names.end(), o.scenario) == names.end())
    throw std::invalid_argument("--scenario: unknown scenario " + io::echo(o.scenario) +
                                " (expected one of: " + joined(names) + ")");
  // Before any simulation: --force replaces only an earlier dataset (or an empty folder), never ".", "..", the
  // home folder or a file; with --format bag only an earlier bag, never a folder or another file.
  if (o.format == "bag") return io::SimBagWriter::checkOutput(o.out, o.force);
  if (o.format == "euroc") return io::EurocDatasetWriter::checkOutput(o.out, o.force);
  io::SimWriterOptions wo;
  wo.overwrite = o.force;
  io::SimDatasetWriter::checkOutput(o.out, wo);
}

// Prints "t / T s (p%), x sim-s/s, ETA" about every 2 s of wall time.
class Progress {
 public:
  Progress(Time start, Time end) : start_(start), end_(end), wall_start_(Clock::now()), last_print_(wall_start_) {}
  void update(Time t) {
    const auto now = Clock::now();
    if (now - last_print_ < std::chrono::seconds(2)) return;
    last_print_ = now;
    const double done = toSeconds(t - start_), total = toSeconds(end_ - start_);
    const double rate = done / std::max(1e-9, wallSeconds());
    spdlog::info("sim {:.1f} / {:.1f} s ({:.0f}%), {:.2f} sim-s/s, ETA {:.0f} s", done, total,
                 100.0 * done / std::max(1e-9, total), rate, rate > 0 ? (total - done) / rate : 0.0);
  }
  double wallSeconds() const { return std::chrono::duration<double>(Clock::now() - wall_start_).count(); }

 private:
  Time start_, end_;
  Clock::time_point wall_start_, last_print_;
};

void writeBag(const SimOptions& o, const sim::Simulator& simulator, Progress& progress, double sim_s) {
  io::SimBagWriter writer(o.out, simulator.datasetDescription(), simulator.groundTruthStates(), o.force);
  simulator.run([&](Measurement&& m) {
    progress.update(measurementTime(m));
    writer.add(std::move(m));
  });
  writer.finish();
  const io::SimBagCounts& c = writer.counts();
  const double wall = progress.wallSeconds(), mb = static_cast<double>(c.bytes) / 1e6;
  spdlog::info("wrote {}: {} IMU samples, {} scans ({:.0f} points each), {} frames, {} ground-truth poses; {:.1f} MB "
               "({:.2f} MB per simulated second); {:.1f} s simulated in {:.1f} s ({:.2f} sim-s/s)",
               o.out, c.imu, c.lidar, c.lidar ? static_cast<double>(c.lidar_points) / c.lidar : 0.0, c.camera,
               c.ground_truth, mb, mb / std::max(1e-9, sim_s), sim_s, wall, sim_s / std::max(1e-9, wall));
}

// EuRoC's ground truth: the pose, the velocity in the world and the IMU's true biases at each stamp.
std::vector<io::EurocTruthState> eurocTruth(const sim::Simulator& simulator) {
  const std::vector<sim::ImuBiasSample> biases = simulator.imuBiases();
  std::vector<io::EurocTruthState> truth;
  std::size_t b = 0;
  for (const io::SimGroundTruthState& g : simulator.groundTruthStates()) {
    while (b + 1 < biases.size() && biases[b + 1].t <= g.t) ++b;  // the bias of the newest IMU sample
    io::EurocTruthState s;
    s.t = g.t;
    s.T_world_imu = g.T_world_imu;
    s.v_world = g.T_world_imu.linear() * g.v_imu;
    if (!biases.empty()) s.gyro_bias = biases[b].gyro, s.accel_bias = biases[b].accel;
    truth.push_back(s);
  }
  return truth;
}

void writeEuroc(const SimOptions& o, const sim::Simulator& simulator, Progress& progress, double sim_s) {
  io::EurocDatasetWriter writer(o.out, simulator.datasetDescription(), o.force);
  simulator.run([&](Measurement&& m) {
    progress.update(measurementTime(m));
    writer.add(std::move(m));
  });
  writer.finish(eurocTruth(simulator));
  const double wall = progress.wallSeconds();
  spdlog::info("wrote {} (EuRoC layout): {} IMU samples, {} frames; {:.1f} s simulated in {:.1f} s ({:.2f} sim-s/s)",
               o.out, writer.imuCount(), writer.frameCount(), sim_s, wall, sim_s / std::max(1e-9, wall));
}

void runSim(const SimOptions& o) {
  if (o.quiet) spdlog::set_level(spdlog::level::err);
  checkOptions(o);
  const sim::SimulatorConfig config = simulatorConfig(o);
  Trajectory kitti05;
  sim::ScenarioOptions so;
  so.seed = o.seed;
  so.duration_s = o.duration;
  if (o.scenario == "kitti05-replay") {
    kitti05 = loadKitti05(o);
    so.kitti05_ground_truth = &kitti05;
  }
  const sim::Scenario scenario = sim::makeScenario(o.scenario, so);
  sim::SimulatorConfig faulted = config;
  for (sim::SensorFault& f : faulted.faults) {  // relative to the trajectory's start, which must contain it
    const Time start = scenario.trajectory->startTime(), end = scenario.trajectory->endTime();
    if (f.start >= end - start)
      throw std::invalid_argument(fmt::format("--fault {} starts at {:.3f} s, after the scenario's end at {:.3f} s",
                                              sim::faultName(f.kind), toSeconds(f.start), toSeconds(end - start)));
    f.start += start;
    f.end += start;
  }
  const sim::Simulator simulator(scenario, faulted, o.seed);
  const sim::Simulator::Counts expected = simulator.expectedCounts();
  spdlog::info("simulating '{}' (seed {}, {:.1f} s, {:.0f} m): {} IMU samples, {} {} sweeps, {} frames -> {}",
               o.scenario, o.seed, toSeconds(scenario.trajectory->endTime() - scenario.trajectory->startTime()),
               scenario.trajectory->pathLength(), expected.imu, expected.lidar, config.lidar.model, expected.camera,
               o.out);
  Progress progress(scenario.trajectory->startTime(), scenario.trajectory->endTime());
  const double sim_s = toSeconds(scenario.trajectory->endTime() - scenario.trajectory->startTime());
  if (o.format == "bag") return writeBag(o, simulator, progress, sim_s);
  if (o.format == "euroc") return writeEuroc(o, simulator, progress, sim_s);
  io::SimWriterOptions wo;
  wo.overwrite = o.force;
  io::SimDatasetWriter writer(o.out, simulator.datasetDescription(), wo);
  simulator.run([&](Measurement&& m) {
    progress.update(measurementTime(m));
    writer.add(std::move(m));
  });
  writer.finish(simulator.groundTruth());
  const io::SimWriterCounts& c = writer.counts();
  const double wall = progress.wallSeconds();
  spdlog::info("wrote {}: {} IMU samples, {} scans ({:.0f} points each), {} frames; {:.1f} s simulated in {:.1f} s "
               "({:.2f} sim-s/s)",
               o.out, c.imu, c.lidar, c.lidar ? static_cast<double>(c.lidar_points) / c.lidar : 0.0, c.camera, sim_s,
               wall, sim_s / std::max(1e-9, wall));
}

}  // namespace

void registerSim(CLI::App& app) {
  auto* cmd = app.add_subcommand("sim", "Generate a simulated dataset (lidar, camera, IMU, ground truth)");
  auto o = std::make_shared<SimOptions>();
  cmd->add_option("--scenario", o->scenario, "Scenario: " + joined(sim::scenarioNames()))->required();
  cmd->add_option("--out", o->out,
                  "Output folder, or bag file with --format bag (written as OUT.partial, renamed when complete)")
      ->required();
  addSeed(cmd, "--seed", o->seed, "Random seed in [0, 2^64 - 1]: the same seed gives byte-identical output")
      ->default_str("1");
  addSeconds(cmd, "--duration", o->duration, between(0, io::kMaxSimDurationS, "s"),
             "Seconds to simulate, up to 3600 (0 = the scenario's natural length; longer: closed courses lap)");
  cmd->add_option("--lidar", o->lidar, "Lidar model (default vlp16 or the config's)")
      ->check(CLI::IsMember({"vlp16", "vlp32", "hdl64"}));
  cmd->add_option_function<std::string>(
      "--camera-rate",
      [o](const std::string& text) {
        const io::ValueSource source = io::ValueSource::option("--camera-rate");
        o->camera_rate = io::checkedRate(io::parseNumber(text, source), io::kMaxSimCameraRateHz, source);
      },
      "Camera frame rate [Hz], up to 60 (default 15 or the config's)");
  cmd->add_option("--format", o->format,
                  "Output format: folder (Drover's layout), or bag: a ROS1 bag with LVI-SAM's topics /points_raw, "
                  "/imu_raw, /camera/image_raw and the ground truth on /ground_truth (nav_msgs/Odometry of the IMU); "
                  "read it with --config config/farm_sim_bag.yaml; or euroc: EuRoC MAV's folder layout (camera + "
                  "IMU, no lidar), read with --format euroc")
      ->check(CLI::IsMember({"folder", "bag", "euroc"}))
      ->capture_default_str();
  cmd->add_option("--config", o->config, "Platform config with a sim: section (config/farm_sim.yaml)");
  cmd->add_option("--kitti-poses", o->kitti_poses, "kitti05-replay: KITTI poses file (default ../shared/data)");
  cmd->add_option("--kitti-times", o->kitti_times, "kitti05-replay: KITTI times.txt (default ../shared/data)");
  cmd->add_flag("--no-camera", o->no_camera, "Do not render camera images");
  cmd->add_option_function<std::vector<std::string>>(
         "--fault",
         [o](const std::vector<std::string>& texts) {
           for (const std::string& text : texts) o->faults.push_back(parseFault(text));
         },
         "Inject a sensor fault, KIND@START+DURATION in seconds from the start (repeatable): camera-blackout (lens "
         "covered), lidar-dropout (no sweeps), imu-gap (no samples), textureless (surfaces without texture); "
         "written into scenario.json")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--force", o->force,
                "Replace an existing output folder that holds an earlier simulated dataset (with --format bag: an "
                "existing ROS bag)");
  cmd->add_flag("-q,--quiet", o->quiet, "Only print errors");
  cmd->callback([o] { runSim(*o); });
}

}  // namespace drover::cli
