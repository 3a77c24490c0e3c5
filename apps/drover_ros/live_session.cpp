// The live Drover behind the ROS node: pipeline::System plus what the node publishes and saves. C++20, no ROS.
#include "apps/drover_ros/live_session.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <stdexcept>
#include <unordered_map>

#include "apps/drover/run_folder.hpp"
#include "apps/drover/run_output.hpp"
#include "apps/drover/run_vis.hpp"
#include "io/config.hpp"
#include "io/odometry/live_config_io.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/output_paths.hpp"
#include "pipeline/stream_clock.hpp"
#include "pipeline/system.hpp"
#include "visual/camera_model.hpp"

namespace drover::live {
namespace {
using Clock = std::chrono::steady_clock;
constexpr std::size_t kSweepLines = 2000;  // sweeps.jsonl of a save: the newest sweeps' lines (~200 s at 10 Hz)

// Voxel-grid downsampling to each occupied voxel's centroid (PCL VoxelGrid's rule); leaf [m].
std::vector<Eigen::Vector3f> voxelDownsample(const std::vector<Eigen::Vector3f>& points, float leaf) {
  struct Cell {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t n = 0;
  };
  std::unordered_map<std::uint64_t, Cell> cells;
  for (const Eigen::Vector3f& p : points) {
    // 21 bits per axis (+-2^20 voxels: +-210 km at a 0.2 m leaf), packed into one key.
    const auto idx = [&](float v) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(std::floor(v / leaf)) + (1 << 20)) & 0x1FFFFF;
    };
    Cell& c = cells[idx(p.x()) | idx(p.y()) << 21 | idx(p.z()) << 42];
    c.sum += p.cast<double>();
    ++c.n;
  }
  std::vector<Eigen::Vector3f> out;
  out.reserve(cells.size());
  for (const auto& [key, c] : cells) out.push_back((c.sum / static_cast<double>(c.n)).cast<float>());
  return out;
}

}  // namespace

struct LiveSession::Impl {
  LiveOptions options;
  LiveCallbacks cb;
  io::DatasetOptions platform;
  pipeline::SystemConfig config;
  std::shared_ptr<visual::KeypointDetector> detector;  // the VIS's, when it runs
  std::string detector_name;
  std::string body_frame;
  Eigen::Isometry3d T_lidar_body = Eigen::Isometry3d::Identity();

  // Swapped by reset(): pushes and reads hold it shared, reset() and shutdown() exclusively.
  mutable std::shared_mutex system_mutex;
  std::unique_ptr<pipeline::System> system;

  // What the callbacks collect for the run folder and the map, since the System started.
  mutable std::mutex record_mutex;
  cli::RunRecord record;
  // By keyframe index: the LIS's own keyframe clouds (lidar frame, [m]), shared, not copied.
  std::vector<std::shared_ptr<const lidar::FeatureSet>> keyframe_clouds;
  std::size_t dropped = 0;
  std::optional<Clock::time_point> first_sweep;  // report.json's wall_s runs from the first sweep's arrival

  // Each stream's newest stamp: a jump back restarts the System before the measurement goes in (none is lost).
  std::unique_ptr<pipeline::StreamClock> clocks;
  std::filesystem::path scratch;          // this session's own temporary folder (the streamed IMU-rate odometry)

  Impl(const LiveOptions& o, LiveCallbacks c);
  ~Impl();
  void start();
  template <class Push>
  void push(pipeline::StreamClock::Stream stream, Time t, const Push& f);
  pipeline::SystemCallbacks systemCallbacks();
};

LiveSession::Impl::~Impl() {
  if (system) system->shutdown();  // its callbacks write into the scratch folder
  std::error_code e;
  std::filesystem::remove_all(scratch, e);
}

LiveSession::Impl::Impl(const LiveOptions& o, LiveCallbacks c) : options(o), cb(std::move(c)) {
  if (options.config.empty()) throw std::invalid_argument("no platform config given (~config)");
  platform = io::loadDatasetOptions(options.config);
  if (!platform.load_lidar)
    throw std::invalid_argument(options.config + ": the platform loads no lidar (dataset.load_lidar): drover_ros runs "
                                "the lidar-inertial system; the VIS alone is not supported live yet");
  config.odometry = io::loadOdometryConfig(options.config);
  if (!platform.load_imu) config.odometry.use_imu = false;  // no IMU will ever come: lidar only from the start
  if (!options.use_loop) config.odometry.loop.enabled = false;
  config.live = io::loadLiveConfig(options.config);  // the node's ~sweep_queue overrides the file's
  config.live.sweep_queue = static_cast<int>(options.sweep_queue);
  if (std::string e = config.live.validate(); !e.empty()) throw std::invalid_argument(e);
  // The VIS runs beside the LIS as in drover run: with images, an IMU and usable intrinsics.
  const std::string no_intrinsics = visual::validateIntrinsics(platform.calibration.camera);
  if (options.use_camera && platform.load_images && platform.load_imu && no_intrinsics.empty()) {
    cli::VisSetup setup = cli::loadVisSetup(options.config, {}, options.working_dir);
    config.vis = setup.config;
    detector = std::move(setup.detector);
    detector_name = setup.detector_name;
  } else if (options.use_camera && platform.load_images && !no_intrinsics.empty() && cb.warning) {
    cb.warning("camera frames ignored, no VIS: the camera has no usable intrinsics (" + no_intrinsics + ") in " +
               options.config);
  }
  body_frame = config.odometry.use_imu ? "imu" : "lidar";
  static std::atomic<int> sessions{0};
  scratch = std::filesystem::temp_directory_path() / fmt::format("drover-live-{}-{}", ::getpid(), sessions++);
  std::filesystem::remove_all(scratch);
  if (!std::filesystem::create_directories(scratch))
    throw std::runtime_error("cannot create the session's scratch folder " + scratch.string());
  if (body_frame == "imu") T_lidar_body = platform.calibration.T_imu_lidar.inverse();
}

pipeline::SystemCallbacks LiveSession::Impl::systemCallbacks() {
  pipeline::SystemCallbacks s;
  s.imu_odometry = [this](const pipeline::ImuOdometry& o) {
    std::shared_ptr<cli::ImuRateFile> file;
    {
      std::lock_guard<std::mutex> lock(record_mutex);
      file = record.imu_rate;
    }
    if (file) file->add(o.t, o.T_world_imu);
    if (cb.imu_odometry) cb.imu_odometry(BodyPose{o.t, o.T_world_imu, o.v_world, true});
  };
  s.sweep = [this](const pipeline::ScanOutcome& o) {
    {
      std::lock_guard<std::mutex> lock(record_mutex);
      record.add(o);
    }
    if (!cb.sweep) return;
    SweepResult r;
    r.pose = BodyPose{o.t, o.T_world_lidar * T_lidar_body, o.v_world, o.has_imu_state};
    r.T_world_lidar = o.T_world_lidar;
    r.keyframe = o.keyframe;
    r.degenerate = o.degenerate;
    r.warning = o.warning;
    r.note = o.note;
    cb.sweep(r);
  };
  s.keyframe = [this](const pipeline::KeyframeRecord& k) {
    std::lock_guard<std::mutex> lock(record_mutex);
    if (keyframe_clouds.size() <= k.index) keyframe_clouds.resize(k.index + 1);
    keyframe_clouds[k.index] = k.features;
    for (std::size_t i : k.retired) keyframe_clouds[i].reset();  // a newer keyframe stands for the place
  };
  s.loop = [this](const pipeline::LoopCorrection& c) {
    if (cb.loop) cb.loop(LoopLink{c.event.query, c.event.candidate, c.event.t_query, c.event.t_candidate});
  };
  s.warning = cb.warning;
  s.deskewed_sweep = cb.deskewed_sweep;
  return s;
}

void LiveSession::Impl::start() {
  {
    std::lock_guard<std::mutex> lock(record_mutex);
    record = cli::RunRecord{};
    // Bounded for long sessions: the newest sweeps' lines, and the IMU-rate odometry streamed to a scratch file
    // (a save copies it).
    record.log.keepNewest(kSweepLines);
    if (config.odometry.use_imu)
      record.imu_rate = std::make_shared<cli::ImuRateFile>((scratch / "trajectory_imu_rate.tum").string(),
                                                           Eigen::Isometry3d::Identity());  // the body is the IMU
    keyframe_clouds.clear();
    dropped = 0;
    first_sweep.reset();
  }
  clocks = std::make_unique<pipeline::StreamClock>(fromSeconds(config.live.clock_jump_s),
                                                   fromSeconds(config.live.sensor_gap_s));
  system = std::make_unique<pipeline::System>(config, platform.calibration, systemCallbacks(), detector);
}

LiveSession::LiveSession(const LiveOptions& options, LiveCallbacks callbacks)
    : impl_(std::make_unique<Impl>(options, std::move(callbacks))) {
  impl_->start();
}

LiveSession::~LiveSession() { shutdown(); }

const io::DatasetOptions& LiveSession::platform() const { return impl_->platform; }
bool LiveSession::visRuns() const { return impl_->config.vis.has_value(); }
const std::string& LiveSession::visDetector() const { return impl_->detector_name; }
const std::string& LiveSession::bodyFrame() const { return impl_->body_frame; }

// Pushes under the shared lock. A measurement whose stream's clock jumped back first restarts the System (a
// System that saw the jump itself would ignore all input from then on), then goes into the new one.
template <class Push>
void LiveSession::Impl::push(pipeline::StreamClock::Stream stream, Time t, const Push& f) {
  pipeline::StreamClock::Verdict v;
  {
    std::shared_lock<std::shared_mutex> lock(system_mutex);
    v = clocks->check(stream, t);
    if (v.kind != pipeline::StreamClock::Kind::kJump) {
      f(*system);
      return;
    }
  }
  {
    std::unique_lock<std::shared_mutex> lock(system_mutex);
    system->shutdown();
    start();
  }
  const std::string why = fmt::format("the {} clock jumped back {:.3f} s ({:.6f} s after {:.6f} s): restarted with "
                                      "an empty map", pipeline::StreamClock::name(stream), toSeconds(v.previous - t),
                                      toSeconds(t), toSeconds(v.previous));
  if (cb.warning) cb.warning(why);
  if (cb.restarted) cb.restarted(why);
  std::shared_lock<std::shared_mutex> lock(system_mutex);
  clocks->check(stream, t);
  f(*system);
}

void LiveSession::pushImu(const ImuSample& sample) {
  impl_->push(pipeline::StreamClock::Stream::kImu, sample.t, [&](pipeline::System& s) { s.pushImu(sample); });
}

void LiveSession::pushSweep(LidarScan scan) {
  const Time t = scan.t;
  impl_->push(pipeline::StreamClock::Stream::kLidar, t, [&](pipeline::System& s) {
    {
      std::lock_guard<std::mutex> record_lock(impl_->record_mutex);
      // On the IMU clock, as trajectory times (drover run's scan_times).
      impl_->record.scan_times.push_back(scan.t + impl_->platform.calibration.lidar_time_offset);
      if (!impl_->first_sweep) impl_->first_sweep = Clock::now();
    }
    s.pushSweep(std::move(scan));
  });
}

void LiveSession::pushFrame(CameraFrame frame) {
  const Time t = frame.t;
  impl_->push(pipeline::StreamClock::Stream::kCamera, t, [&](pipeline::System& s) { s.pushFrame(std::move(frame)); });
}

void LiveSession::dropped(const std::string& notice) {
  std::size_t n = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->record_mutex);
    n = ++impl_->dropped;
  }
  // A driver whose every message is unreadable must not flood the log: the first ten, then every hundredth.
  if (impl_->cb.warning && (n <= 10 || n % 100 == 0))
    impl_->cb.warning(fmt::format("{} ({} messages dropped so far)", notice, n));
}

LiveView LiveSession::view(float map_leaf) const {
  LiveView v;
  Trajectory lidar;
  {
    std::shared_lock<std::shared_mutex> lock(impl_->system_mutex);
    impl_->system->inspect([&](const pipeline::LidarOdometry& lis, const pipeline::LoopClosure* loops) {
      lidar = lis.keyframeTrajectory();
      for (const pipeline::LoopEvent& e : (loops != nullptr ? *loops : lis.loopClosure()).events())
        if (e.verification.accepted) v.loops.push_back({e.query, e.candidate, e.t_query, e.t_candidate});
    });
  }
  for (const StampedPose& k : lidar) v.keyframes.push_back({k.t, k.T_world_body * impl_->T_lidar_body});
  if (map_leaf <= 0) return v;
  std::vector<Eigen::Vector3f> world;
  {
    std::lock_guard<std::mutex> lock(impl_->record_mutex);
    for (std::size_t i = 0; i < lidar.size() && i < impl_->keyframe_clouds.size(); ++i) {
      const Eigen::Isometry3f T = lidar[i].T_world_body.cast<float>();
      if (impl_->keyframe_clouds[i])
        for (const Eigen::Vector3f& p : impl_->keyframe_clouds[i]->full) world.push_back(T * p);
    }
  }
  v.map = voxelDownsample(world, map_leaf);
  return v;
}

std::string LiveSession::save(const std::string& dir, const std::string& end) {
  Impl& m = *impl_;
  cli::RunRecord r;
  double wall_s = 0;
  {
    std::lock_guard<std::mutex> lock(m.record_mutex);
    r = m.record;
    r.measurements_dropped = m.dropped;
    if (m.first_sweep) wall_s = std::chrono::duration<double>(Clock::now() - *m.first_sweep).count();
  }
  if (r.sweeps == 0)
    throw std::invalid_argument("nothing to save yet: no sweep has produced a pose (" + summary() + ")");
  r.end = end;
  r.wall_s = wall_s;
  r.data_s = toSeconds(r.last_t - r.first_t);
  io::StagedFolder folder(dir, cli::runFolderRules());
  io::GroundTruth none;        // live: no ground truth; the body frame sets trajectory.tum's frame
  none.body_frame = m.body_frame;
  std::string line;
  std::shared_lock<std::shared_mutex> lock(m.system_mutex);
  r.measurements_dropped += m.system->stats().sweeps_dropped + m.system->stats().frames_dropped;
  const std::string topics = "ROS topics " + m.platform.lidar_topic +
                             (m.platform.load_imu ? ", " + m.platform.imu_topic : std::string());
  const cli::RunContext context{topics, "ros", m.options.config, dir, m.platform.calibration, none,
                                folder.dir().string()};
  m.system->inspect([&](const pipeline::LidarOdometry& lis, const pipeline::LoopClosure* loops) {
    const cli::LiveRun live{loops, nullptr};
    cli::writeRunFolder(context, lis, r, nullptr, &live);
    line = fmt::format("{} sweeps, {} keyframes", lis.stats().scans_processed, lis.stats().keyframes);
  });
  folder.publish();
  return fmt::format("saved {} to {}", line, folder.out().string());
}

void LiveSession::reset() {
  std::unique_lock<std::shared_mutex> lock(impl_->system_mutex);
  impl_->system->shutdown();
  impl_->start();
}

void LiveSession::shutdown() {
  std::unique_lock<std::shared_mutex> lock(impl_->system_mutex);
  if (impl_->system) impl_->system->shutdown();
}

std::string LiveSession::summary() const {
  std::shared_lock<std::shared_mutex> lock(impl_->system_mutex);
  const pipeline::SystemStats s = impl_->system->stats();
  std::size_t processed = 0, keyframes = 0;
  {
    std::lock_guard<std::mutex> record_lock(impl_->record_mutex);
    processed = impl_->record.sweeps;
    keyframes = impl_->keyframe_clouds.size();
  }
  return fmt::format("{} sweeps pushed, {} processed, {} dropped (LIS behind); {} keyframes; {} IMU samples; {} loop "
                     "corrections applied", s.sweeps_pushed, processed, s.sweeps_dropped, keyframes, s.imu_pushed,
                     s.loops_applied);
}

}  // namespace drover::live
