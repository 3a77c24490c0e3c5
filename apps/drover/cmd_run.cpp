// drover run: lidar(-inertial) odometry over a dataset, written into a run folder. The odometry is
// pipeline::LidarOdometry; this file reads the dataset, shows progress, writes the files and evaluates.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "apps/drover/heap_tuning.hpp"
#include "apps/drover/run_folder.hpp"
#include "apps/drover/run_output.hpp"
#include "apps/drover/run_preset.hpp"
#include "apps/drover/run_progress.hpp"
#include "apps/drover/run_realtime.hpp"
#include "apps/drover/run_vis.hpp"
#include "io/config.hpp"
#include "io/dataset.hpp"
#include "io/odometry/imu_noise_check.hpp"
#include "io/odometry/live_config_io.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/read_ahead.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "visual/camera_model.hpp"

namespace drover::cli {
namespace {

// Measurements the main loop reads ahead of its own position, so that the VIS's front end can track a frame while
// the loop processes the ~13 IMU samples and the sweep before it (~2 camera frames at 200 Hz IMU and 15 Hz camera).
constexpr std::size_t kLookahead = 32;

namespace fs = std::filesystem;

struct RunOptions {
  std::string dataset, format, config, out, preset;
  std::vector<std::string> without;  // --without: parts taken out after the preset
  MethodChoice method() const { return {presetFromName(preset), without}; }
  bool no_imu = false, no_camera = false, no_lidar = false, no_loop = false, quiet = false, realtime = false;
  double start = 0, duration = 0;  // [s] from the first measurement; duration 0 = to the end
  double rate = 1.0;               // [-] --realtime: sensor seconds per wall second
  std::size_t max_frames = 0;      // KITTI odometry: first N frames only
};

io::DatasetOptions datasetOptions(const RunOptions& o) {
  io::DatasetOptions d = o.config.empty() ? io::DatasetOptions{} : io::loadDatasetOptions(o.config);
  if (o.no_imu) d.load_imu = false;
  if (o.no_lidar) d.load_lidar = false;
  // Images are decoded only for the VIS, which is visual-inertial: not without an IMU (KITTI odometry has none).
  if (o.no_camera || o.no_imu || o.format == "kitti") d.load_images = false;
  d.kitti_max_frames = o.max_frames;
  return d;
}

// --start and --duration were checked when the command line was read (addSeconds).
void checkOptions(const RunOptions& o) {
  if (!fs::exists(o.dataset)) throw std::invalid_argument("dataset " + o.dataset + " not found");
  if (o.no_lidar && o.no_camera)
    throw std::invalid_argument("--no-lidar with --no-camera leaves nothing to run: drover run needs a lidar or a camera");
  if (o.no_lidar && o.no_imu)
    throw std::invalid_argument("--no-lidar with --no-imu: the VIS is visual-inertial and needs the IMU");
  if (o.realtime && o.no_lidar)
    throw std::invalid_argument("--realtime with --no-lidar: the real-time replay runs the LIS and loop closure; the "
                                "VIS alone runs in the deterministic replay (drop --realtime)");
  if (o.rate != 1.0 && !o.realtime)
    throw std::invalid_argument("--rate sets the speed of the --realtime replay; without --realtime the run goes as "
                                "fast as the computer allows");
  io::StagedFolder::check(o.out, runFolderRules());  // before any work: a foreign or unusable --out costs nothing
}

void keep(std::vector<pipeline::ScanOutcome>&& outcomes, RunRecord& record) {
  for (pipeline::ScanOutcome& s : outcomes) {
    if (!s.warning.empty()) spdlog::warn("sweep at {:.3f} s: {}", toSeconds(s.t), s.warning);
    if (!s.note.empty()) spdlog::info("sweep at {:.3f} s: {}", toSeconds(s.t), s.note);
    record.add(s);
  }
}

// What the run actually fuses, said once the first sweep has decided it (the IMU is initialised at that sweep,
// or given up: an empty IMU file, or data that starts too late, means lidar only -- a warning when it was asked for).
void announceFusion(const pipeline::LidarOdometry& odometry, const RunOptions& o) {
  const pipeline::OdometryStats& s = odometry.stats();
  const std::string loop = odometry.config().loop.enabled ? ", loop closure" : "";
  if (!odometry.config().use_imu)
    spdlog::info("fusing: lidar only{} ({})", loop, o.no_imu ? "--no-imu" : "odometry.use_imu is false");
  else if (s.imu_initialized)
    spdlog::info("fusing: lidar + IMU{}; IMU {}", loop, s.imu_init);
  else if (s.imu.accepted == 0)
    spdlog::warn("fusing: lidar only{}: the dataset gave no IMU sample{}", loop,
                 o.format == "kitti" ? " (KITTI odometry has no IMU)" : " (is its IMU file or topic empty?)");
  else
    spdlog::warn("fusing: lidar only{}: {}", loop, s.imu_init);
}

// Prints the odometry's new notices (skipped sweeps, IMU problems) and, at the first pose, what is fused.
void showNotices(const pipeline::LidarOdometry& odometry, const RunOptions& o, RunRecord& record) {
  const std::vector<std::string>& notices = odometry.stats().notices;
  for (; record.notices_shown < notices.size(); ++record.notices_shown) spdlog::warn("{}", notices[record.notices_shown]);
  if (!record.fusion_announced && odometry.stats().scans_processed > 0) {
    announceFusion(odometry, o);
    record.fusion_announced = true;
  }
}

// A run in which no sweep produced a pose is a failure with its reason, not an empty success.
void checkSomethingWasDone(const pipeline::OdometryStats& s, const RunOptions& o, const RunVis* vis) {
  const std::string window = o.start > 0 || o.duration > 0 ? " in the --start/--duration window" : "";
  if (o.no_lidar) {
    if (vis == nullptr || vis->framesIn() == 0)
      throw std::invalid_argument("dataset " + o.dataset + " has no camera frames" + window +
                                  ": drover run --no-lidar runs the VIS, which needs a camera and an IMU");
    if (vis->framesEstimated() == 0)
      throw std::invalid_argument(fmt::format("{}: the VIS did not initialise in {} camera frames{}: {}", o.dataset,
                                              vis->framesIn(), window, vis->waitingReason()));
    return;
  }
  if (s.scans_in == 0)
    throw std::invalid_argument("dataset " + o.dataset + " has no lidar scans" + window +
                                ": drover run needs a lidar, or --no-lidar to run the VIS alone (camera + IMU)");
  if (s.scans_processed == 0)
    throw std::invalid_argument(fmt::format(
        "{}: no sweep produced a pose{}: of {} sweeps, {} had too few valid points (odometry.min_points) and {} a "
        "stamp not after the previous sweep's; {} points were dropped as non-finite or out of range",
        o.dataset, window, s.scans_in, s.scans_skipped_empty, s.scans_skipped_time, s.points_dropped));
}

// A camera without usable intrinsics (a bag whose platform config gives none): the VIS cannot run. Beside the LIS
// that is one warning and the frames are ignored; for the VIS alone it is an error naming the config.
bool cameraUsable(const Calibration& calibration, bool no_lidar, const RunOptions& o, bool& warned) {
  const std::string why = visual::validateIntrinsics(calibration.camera);
  if (why.empty()) return true;
  const std::string where = o.config.empty() ? o.dataset : o.config;
  if (no_lidar)
    throw std::invalid_argument(where + ": the camera has no usable intrinsics (" + why +
                                "): the VIS needs them (the platform config's calibration.camera section)");
  if (!warned)
    spdlog::warn("camera frames ignored, no VIS: the camera has no usable intrinsics ({}); give them in {}'s "
                 "calibration.camera section", why, where);
  warned = true;
  return false;
}

// A EuRoC sequence says what its IMU's noise is; the estimators use the config's. A config written for another IMU
// gets a warning per figure that is off by more than io::kImuNoiseReportFactor.
void warnOfImuNoise(const RunOptions& o, const imu::PreintegrationConfig& used) {
  if (o.format != "euroc") return;
  const std::string config_name = o.config.empty() ? "built-in default" : o.config;
  for (const std::string& line : io::imuNoiseDisagreements(io::readEurocImuNoise(o.dataset), used, config_name))
    spdlog::warn("{}", line);
}

// --realtime: the dataset at sensor rate through pipeline::System (threads, bounded queues), then the same files.
void runRealtimeOdometry(const RunOptions& o, const pipeline::OdometryConfig& config, io::Reader& reader) {
  pipeline::SystemConfig system_config;
  system_config.odometry = config;
  if (!o.config.empty()) system_config.live = io::loadLiveConfig(o.config);
  RealtimeOptions options{o.start, o.duration, o.rate, nullptr, nullptr};
  std::unique_ptr<RunVis> vis;  // with images, an IMU and usable intrinsics: the VIS in its own thread
  const bool camera = visual::validateIntrinsics(reader.calibration().camera).empty();
  if (camera && !o.no_camera && !o.no_imu && o.format != "kitti") {
    VisSetup setup = loadVisSetup(o.config, o.method());
    system_config.vis = setup.config;
    options.detector = setup.detector;
    vis = std::make_unique<RunVis>(setup);
    options.vis = vis.get();
  }
  spdlog::info("drover run --realtime: {} ({}) at sensor rate -> {}", reader.describe(), o.format, o.out);
  StopOnSignal stop;
  // Staged from the start: the per-sweep lines and the IMU-rate odometry are streamed into it (a failed run leaves
  // nothing behind, as StagedFolder removes OUT.partial unless published).
  io::StagedFolder folder(o.out, runFolderRules());
  RunContext context{o.dataset, o.format, o.config, o.out, reader.calibration(), reader.groundTruth(),
                     folder.dir().string(),
                     o.method().describe()};
  RealtimeRun run;
  streamRunFiles(context, run.record, config.use_imu);
  if (vis) streamVisFiles(context, *vis);
  runRealtime(reader, system_config, options, stop, run);
  if (vis && vis->framesIn() == 0) vis.reset();  // no camera frames came: no VIS files
  const pipeline::LidarOdometry& lis = run.system->lis();
  checkSomethingWasDone(lis.stats(), o, nullptr);
  const LiveRun live{run.system->loopClosure(), run.realtime};
  writeRunFolder(context, lis, run.record, vis.get(), &live);
  folder.publish();
  const auto ms = [&run](const char* output, const char* stat) {  // null (no output at all) prints as 0
    const auto& v = run.realtime["latency_ms"][output][stat];
    return v.is_null() ? 0.0 : v.get<double>();
  };
  spdlog::info("realtime: latency sweep end -> pose p50 {:.1f} / p95 {:.1f} / max {:.1f} ms; IMU sample -> pose p95 "
               "{:.3f} ms; {} of {} sweeps dropped",
               ms("sweep", "p50"), ms("sweep", "p95"), ms("sweep", "max"), ms("imu_rate", "p95"),
               run.realtime["sweeps_dropped"].get<std::size_t>(), run.realtime["sweeps_pushed"].get<std::size_t>());
  if (stop.requested()) throw ExitCode{128 + stop.signal()};
}

void runOdometry(const RunOptions& o) {
  if (o.quiet) spdlog::set_level(spdlog::level::err);
  checkOptions(o);
  pipeline::OdometryConfig config = o.config.empty() ? pipeline::OdometryConfig{} : io::loadOdometryConfig(o.config);
  o.method().apply(config);
  if (o.no_imu) config.use_imu = false;
  if (o.no_loop) config.loop.enabled = false;
  const io::DatasetOptions dataset_options = datasetOptions(o);
  std::unique_ptr<io::Reader> reader = io::openDataset(o.dataset, o.format, dataset_options);
  warnOfImuNoise(o, config.preintegration);
  if (o.realtime) return runRealtimeOdometry(o, config, *reader);
  // Decoding images and parsing lidar files in a thread of their own, ahead of the odometry: the same stream.
  reader = io::readAhead(std::move(reader));
  // --no-lidar, or a platform whose dataset section loads no lidar (EuRoC): the VIS alone.
  const bool no_lidar = o.no_lidar || (!dataset_options.load_lidar && !o.no_camera);
  if (no_lidar)
    spdlog::info("fusing: camera + IMU, the VIS alone ({})",
                 o.no_lidar ? "--no-lidar" : "the platform config loads no lidar");
  const io::GroundTruth& gt = reader->groundTruth();
  pipeline::LidarOdometry odometry(config, reader->calibration());
  spdlog::info("drover run: {} ({}) -> {}", reader->describe(), o.format, o.out);
  // Written as OUT.partial from the start (the per-sweep lines and the IMU-rate odometry are streamed into it) and
  // renamed at the end: a run that fails on its data leaves no folder behind, one killed while writing leaves an
  // earlier run in OUT whole.
  io::StagedFolder folder(o.out, runFolderRules());
  RunContext context{o.dataset, o.format, o.config, o.out, reader->calibration(), gt, folder.dir().string(),
                     o.method().describe()};

  const double gt_span = gt.poses.size() > 1 ? toSeconds(gt.poses.back().t - gt.poses.front().t) : 0.0;
  const double total = o.duration > 0 ? (gt_span > 0 ? std::min(o.duration, gt_span - o.start) : o.duration)
                                      : std::max(0.0, gt_span - o.start);
  RunProgress progress(total);
  RunRecord record;
  if (!no_lidar) {
    streamRunFiles(context, record, config.use_imu);
    if (record.imu_rate)
      odometry.setImuRateListener([&record](const StampedPose& p) { record.imu_rate->add(p.t, p.T_world_body); });
  }
  std::optional<Time> t_first;
  const auto showReaderDrops = [&] {
    const io::ReaderDrops& drops = reader->drops();
    for (; record.reader_notices_shown < drops.notices.size(); ++record.reader_notices_shown)
      spdlog::warn("{}", drops.notices[record.reader_notices_shown]);
    record.measurements_dropped = drops.measurements;
  };
  std::size_t scans_read = 0;  // lidar scans the reader gave, before --start included
  StopOnSignal stop;           // SIGINT/SIGTERM: stop reading and write what was processed
  std::unique_ptr<RunVis> vis;  // made at the first camera frame (a dataset without images runs the LIS alone)
  std::optional<ImuSample> last_imu;
  bool camera_warned = false;
  // The VIS's front end runs ahead in a thread of its own (track_ahead.hpp): every frame the loop below will give
  // the VIS is submitted when it is read, a few measurements before its turn.
  std::optional<VisSetup> vis_setup;
  std::unique_ptr<TrackAhead> track_ahead;
  const auto visTakes = [&](const CameraFrame& frame) {
    const double since = toSeconds(frame.t - *t_first);
    return since >= o.start && !(o.duration > 0 && since > o.start + o.duration) &&
           cameraUsable(reader->calibration(), no_lidar, o, camera_warned);
  };
  const auto onRead = [&](const Measurement& m) {
    if (!t_first) t_first = measurementTime(m);
    const auto* frame = std::get_if<CameraFrame>(&m);
    if (frame == nullptr || !visTakes(*frame)) return;
    if (!track_ahead) {
      vis_setup = loadVisSetup(o.config, o.method());
      track_ahead = std::make_unique<TrackAhead>(reader->calibration(), vis_setup->detector, vis_setup->config.tracker);
    }
    track_ahead->submit(*frame);
  };
  Lookahead ahead(*reader, kLookahead);
  const auto visFor = [&]() -> RunVis& {
    if (!vis) {
      vis = std::make_unique<RunVis>(*vis_setup, reader->calibration(), config.preintegration);
      streamVisFiles(context, *vis);
      if (last_imu) vis->onImu(*last_imu);  // the first frame's interval starts at the sample before it
      if (!no_lidar)
        odometry.setSweepListener([&vis](Time t, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& p) {
          vis->onSweep(t, T, p);
        });
    }
    return *vis;
  };
  HeapTrimmer heap;  // an hour-long replay returns its fragmented free pages every 30 s of data
  while (std::optional<Measurement> m = stop.requested() ? std::nullopt : ahead.next(onRead)) {
    showReaderDrops();
    const Time t = measurementTime(*m);
    heap.tick(t);
    if (!t_first) t_first = t;
    const double since = toSeconds(t - *t_first);
    scans_read += std::holds_alternative<LidarScan>(*m) ? 1 : 0;
    if (since < o.start) continue;
    if (o.duration > 0 && since > o.start + o.duration) {
      record.end = "--duration reached";
      break;
    }
    if (const auto* scan = std::get_if<LidarScan>(&*m))
      record.scan_times.push_back(scan->t + reader->calibration().lidar_time_offset);
    if (const auto* frame = std::get_if<CameraFrame>(&*m)) {
      if (!visTakes(*frame)) continue;  // what onRead submitted by: this frame is the oldest submitted
      visFor().onFrame(*frame, no_lidar ? nullptr : &odometry, track_ahead.get());
      if (!no_lidar)
        if (std::optional<pipeline::VisualState> state = vis->takeState()) odometry.addVisualState(*state);
      continue;
    }
    if (const auto* sample = std::get_if<ImuSample>(&*m)) {
      last_imu = *sample;
      if (vis) vis->onImu(*sample);
    }
    if (no_lidar) continue;
    std::vector<pipeline::ScanOutcome> outcomes = odometry.process(*m);
    if (vis)
      for (const pipeline::ScanOutcome& s : outcomes) vis->onLisState(s);
    keep(std::move(outcomes), record);
    showNotices(odometry, o, record);
    progress.update(record.sweeps, since - o.start);
  }
  showReaderDrops();
  if (o.max_frames > 0 && o.format == "kitti" && scans_read >= o.max_frames) record.end = "--max-frames reached";
  const int interrupted_by = stop.signal();  // a signal after the reading is done changes nothing
  if (interrupted_by) record.end = "interrupted by " + signalName(interrupted_by);
  if (!no_lidar) keep(odometry.finish(), record);
  showNotices(odometry, o, record);
  RunOptions ran = o;
  ran.no_lidar = no_lidar;
  checkSomethingWasDone(odometry.stats(), ran, vis.get());
  record.wall_s = progress.wallSeconds();
  record.data_s = record.sweeps > 1 ? toSeconds(record.last_t - record.first_t) : 0.0;
  if (ran.no_lidar) writeVisRunFolder(context, *vis, record);
  else writeRunFolder(context, odometry, record, vis.get());
  folder.publish();
  if (!interrupted_by) return;
  spdlog::warn("{}: wrote the {} sweeps processed before it to {}", record.end, record.sweeps, o.out);
  throw ExitCode{128 + interrupted_by};  // as a shell reports a command a signal ended
}

}  // namespace

void registerRun(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "run", "Lidar-inertial odometry with loop closure over a dataset; writes trajectory, map and report");
  auto o = std::make_shared<RunOptions>();
  cmd->add_option("dataset", o->dataset, "Dataset folder or bag file")->required();
  cmd->add_option("--format", o->format, "Dataset format")
      ->required()
      ->check(CLI::IsMember({"kitti", "kitti-raw", "euroc", "bag", "sim"}));
  cmd->add_option("--config", o->config, "Platform config (config/kitti.yaml, farm_sim.yaml, ...)");
  cmd->add_option("--out", o->out, "Run folder (written as OUT.partial, renamed when complete; replaces only an "
                                  "earlier run folder)")->required();
  cmd->add_option("--preset", o->preset,
                  "Methods of the paper's comparison over the platform config (which still sets the sensors): "
                  "drover (SuperPoint, lidar depth factors, the VIS's motion as a factor, Scan Context with the VIS's "
                  "yaw beside the radius search, a 4-DoF pose graph) or lvi-sam (Shi-Tomasi, fixed lidar depth, the VIS's "
                  "motion as the guess only, radius loops, a 6-DoF pose graph); "
                  "default: the platform config's own choices")
      ->check(CLI::IsMember(presetNames()));
  cmd->add_option("--without", o->without,
                  "Take a part out after the preset (repeatable; the ablation): vo-factor, vis-guess, vis-gates, "
                  "visual-yaw-prior, scan-context, radius-search, four-dof, loop-fitness-sigma, vis-carried-sigma, "
                  "depth-factor, superpoint, lk-min-eigenvalue, keyframe-interval, keyframe-gap-speed, "
                  "lidar-rotation-sigma")
      ->check(CLI::IsMember(partNames()));
  cmd->add_flag("--no-imu", o->no_imu, "Lidar only: ignore the IMU (constant-velocity deskew and guess)");
  cmd->add_flag("--no-loop", o->no_loop, "No loop closure (odometry only; the keyframe graph is still kept)");
  cmd->add_flag("--no-camera", o->no_camera, "Ignore the camera: the LIS alone (no VIS)");
  cmd->add_flag("--no-lidar", o->no_lidar,
                "Ignore the lidar: the VIS alone (camera + IMU, visual-inertial initialisation)");
  addSeconds(cmd, "--start", o->start, atLeast(0, "s"), "Skip the first S seconds of the dataset");
  addSeconds(cmd, "--duration", o->duration, atLeast(0, "s"), "Process S seconds after --start (0 = to the end)");
  addInteger(cmd, "--max-frames", o->max_frames, 1, 1'000'000'000,
             "KITTI odometry: read only the first N >= 1 frames of times.txt");
  cmd->add_flag("--realtime", o->realtime,
                "Replay at sensor rate through the live system (threads, bounded queues: a slow stage drops sweeps); "
                "report.json gains latency per output and the sweeps dropped");
  addNumber(cmd, "--rate", o->rate, between(0.01, 100, "x"),
            "With --realtime: play the data R times as fast as recorded (0.5: half speed, as rosbag play -r)");
  cmd->add_flag("-q,--quiet", o->quiet, "Only print errors");
  cmd->callback([o] { runOdometry(*o); });
}

}  // namespace drover::cli
