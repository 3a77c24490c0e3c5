#include "pipeline/system.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <variant>

#include "imu/propagator.hpp"
#include "pipeline/lis_seed.hpp"
#include "pipeline/live_queue.hpp"
#include "pipeline/loop_worker.hpp"

namespace drover::pipeline {
namespace {

constexpr Time kBoardSpan = 10'000'000'000;  // [ns] IMU-rate poses kept for the VIS's lookups
constexpr std::size_t kShownDrops = 10;      // drop warnings printed; then every kDropEvery-th

bool accepted(imu::SampleStatus s) {
  return s == imu::SampleStatus::kAccepted || s == imu::SampleStatus::kAcceptedAfterGap;
}

// A deskewed sweep for the VIS's lidar depth.
struct DepthSweep {
  Time t = 0;
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  std::vector<Eigen::Vector3f> points_lidar;
};
// A loop correction moved the LIS's world: the VIS's buffered sweeps follow.
struct WorldCorrection {
  Eigen::Isometry3d T_new_old = Eigen::Isometry3d::Identity();
};
using VisItem = std::variant<ImuSample, CameraFrame, DepthSweep, WorldCorrection>;

}  // namespace

std::string LiveConfig::validate() const {
  if (sweep_queue < 1) return "live.sweep_queue must be >= 1";
  if (frame_queue < 1) return "live.frame_queue must be >= 1";
  if (!std::isfinite(loop_rate_hz) || loop_rate_hz <= 0) return "live.loop_rate_hz must be > 0";
  return "";
}

struct System::Impl {
  SystemConfig config;
  SystemCallbacks cb;
  LidarOdometry lis;
  std::unique_ptr<LoopWorker> loops;
  std::unique_ptr<vio::VisualOdometry> vo;

  // IMU front: the pushing thread's propagation, re-anchored on the LIS's fused state.
  std::mutex imu_mutex;
  imu::ImuPropagator propagator;
  bool anchored = false;

  // What the VIS reads of the LIS (its own thread): recent IMU-rate poses, the newest fused biases.
  std::mutex board_mutex;
  std::deque<StampedPose> imu_rate;
  std::optional<imu::ImuBias> lis_bias;
  std::size_t lis_sweeps = 0;
  bool lis_imu_initialized = false;

  // Held by the LIS thread while it changes the LIS, and by the loop thread while it searches: inspect() takes both.
  mutable std::mutex lis_state_mutex, loop_state_mutex;

  LiveQueue<Measurement> lis_queue;
  LiveQueue<VisItem> vis_queue;
  // Keyframes for the loop thread, and the newest correction for the LIS (a later one contains the earlier).
  std::mutex loop_mutex;
  std::condition_variable loop_wake;
  std::vector<KeyframeRecord> keyframes;
  bool loop_stop = false;
  std::optional<LoopCorrection> correction;
  std::atomic<bool> has_correction{false};

  mutable std::mutex stats_mutex;
  SystemStats stats;
  std::atomic<bool> stopped{false};
  bool joined = false;
  std::thread lis_thread, loop_thread, vis_thread;

  Impl(const SystemConfig& c, const Calibration& calibration, SystemCallbacks callbacks,
       std::shared_ptr<visual::KeypointDetector> detector)
      : config(c), cb(std::move(callbacks)), lis(c.odometry, calibration), propagator(c.odometry.propagator) {
    if (std::string e = c.live.validate(); !e.empty()) throw std::invalid_argument("live config: " + e);
    if (c.odometry.loop.enabled) loops = std::make_unique<LoopWorker>(c.odometry.loop, c.odometry.local_map);
    if (c.vis && detector) {
      // Live, the detector runs in the tracker's worker thread (SuperPoint takes ~0.4 s a frame here): KLT tracks
      // every frame meanwhile. The replay keeps it synchronous, hence deterministic.
      vio::VisConfig vis = *c.vis;
      vis.tracker.async_detection = true;
      vo = std::make_unique<vio::VisualOdometry>(vis, calibration, c.odometry.preintegration, std::move(detector));
    }
    lis.setKeyframeListener([this](const KeyframeRecord& k) { onKeyframe(k); }, loops != nullptr);
    if (vo)
      lis.setSweepListener([this](Time t, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& p) {
        vis_queue.push(DepthSweep{t, T, p}, false, 0);
      });
  }

  void warn(const std::string& line) {
    if (cb.warning) cb.warning(line);
  }
  void countDrop(std::size_t SystemStats::*counter, const char* stage, const char* what) {
    std::size_t n = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex);
      n = ++(stats.*counter);
    }
    if (n <= kShownDrops || n % 100 == 0)
      warn(fmt::format("live: {} fell behind: the oldest waiting {} dropped ({} so far)", stage, what, n));
  }

  void onImu(const ImuSample& sample);
  void onKeyframe(const KeyframeRecord& k);
  void lisLoop();
  void publish(std::vector<ScanOutcome>&& outcomes);
  void applyCorrection();
  void loopLoop();
  void visLoop();
  void visFrame(const CameraFrame& frame);
  void stop();
};

void System::Impl::onImu(const ImuSample& sample) {
  std::optional<ImuOdometry> out;
  {
    std::lock_guard<std::mutex> lock(imu_mutex);
    const imu::SampleStatus status = propagator.addSample(sample);
    if (anchored && accepted(status))
      if (const std::optional<imu::NavState> s = propagator.stateAt(sample.t))
        out = ImuOdometry{sample.t, s->T_world_imu, s->v_world};
  }
  if (!out) return;
  {
    std::lock_guard<std::mutex> lock(board_mutex);
    imu_rate.push_back({out->t, out->T_world_imu});
    while (imu_rate.size() > 2 && imu_rate.back().t - imu_rate.front().t > kBoardSpan) imu_rate.pop_front();
  }
  if (cb.imu_odometry) cb.imu_odometry(*out);
}

void System::Impl::onKeyframe(const KeyframeRecord& k) {
  if (loops) {
    std::lock_guard<std::mutex> lock(loop_mutex);
    keyframes.push_back(k);
  }
  if (cb.keyframe) cb.keyframe(k);
}

void System::Impl::lisLoop() {
  while (std::optional<Measurement> m = lis_queue.pop()) {
    std::vector<ScanOutcome> outcomes;
    {
      std::lock_guard<std::mutex> lock(lis_state_mutex);
      applyCorrection();
      outcomes = lis.process(*m);
    }
    publish(std::move(outcomes));
  }
  std::vector<ScanOutcome> outcomes;
  {
    std::lock_guard<std::mutex> lock(lis_state_mutex);
    applyCorrection();
    outcomes = lis.finish();
  }
  publish(std::move(outcomes));
}

// Re-anchors the IMU front on the newest fused state, tells the VIS's board, calls back.
void System::Impl::publish(std::vector<ScanOutcome>&& outcomes) {
  if (outcomes.empty()) return;
  std::optional<imu::FusedState> fused;
  std::size_t processed = 0;
  bool imu_initialized = false;
  {
    // LidarOdometry::stats() refreshes its IMU counters: not while inspect() reads the LIS from another thread.
    std::lock_guard<std::mutex> lock(lis_state_mutex);
    fused = lis.fusedImuState();
    processed = lis.stats().scans_processed;
    imu_initialized = lis.stats().imu_initialized;
  }
  if (fused) {
    std::lock_guard<std::mutex> lock(imu_mutex);
    propagator.reset(fused->state, fused->bias);
    anchored = true;
  }
  {
    std::lock_guard<std::mutex> lock(board_mutex);
    for (const ScanOutcome& o : outcomes)
      if (o.has_imu_state) lis_bias = imu::ImuBias{o.gyro_bias, o.acc_bias};
    lis_sweeps = processed;
    lis_imu_initialized = imu_initialized;
  }
  if (cb.sweep)
    for (const ScanOutcome& o : outcomes) cb.sweep(o);
}

void System::Impl::applyCorrection() {
  if (!has_correction.load()) return;
  std::optional<LoopCorrection> c;
  {
    std::lock_guard<std::mutex> lock(loop_mutex);
    c.swap(correction);
    has_correction = false;
  }
  if (!c) return;
  const Eigen::Isometry3d T_new_old = lis.applyLoopCorrection(*c);
  if (vo) vis_queue.push(WorldCorrection{T_new_old}, false, 0);
  std::lock_guard<std::mutex> lock(stats_mutex);
  ++stats.loops_applied;
}

// Wakes every 1 / loop_rate_hz and searches every keyframe made since, in order; at shutdown, the rest.
void System::Impl::loopLoop() {
  const auto period = std::chrono::duration<double>(1.0 / config.live.loop_rate_hz);
  for (;;) {
    std::vector<KeyframeRecord> batch;
    bool last = false;
    {
      std::unique_lock<std::mutex> lock(loop_mutex);
      loop_wake.wait_for(lock, period, [this] { return loop_stop; });
      batch.swap(keyframes);
      last = loop_stop;
    }
    for (const KeyframeRecord& k : batch) {
      std::optional<LoopCorrection> c;
      {
        std::lock_guard<std::mutex> lock(loop_state_mutex);
        c = loops->add(k);
      }
      if (!c) continue;
      if (cb.loop) cb.loop(*c);
      std::lock_guard<std::mutex> lock(loop_mutex);
      correction = std::move(c);
      has_correction = true;
    }
    if (last) return;
  }
}

void System::Impl::visLoop() {
  while (std::optional<VisItem> item = vis_queue.pop()) {
    if (const auto* s = std::get_if<ImuSample>(&*item)) vo->addImu(*s);
    else if (const auto* d = std::get_if<DepthSweep>(&*item)) vo->addSweep(d->t, d->T_world_lidar, d->points_lidar);
    else if (const auto* w = std::get_if<WorldCorrection>(&*item)) vo->onWorldCorrected(w->T_new_old);
    else visFrame(std::get<CameraFrame>(*item));
  }
}

// As the replay's RunVis::onFrame: the LIS's pose and state from the board; the VIS waits for the LIS's seed
// while the LIS may still give one.
void System::Impl::visFrame(const CameraFrame& frame) {
  vio::VisualOdometry::PoseAt pose_at;
  vio::Seeder seed;
  if (config.use_lidar) {
    pose_at = [this](Time t) {
      std::lock_guard<std::mutex> lock(board_mutex);
      return lisPoseAt(imu_rate, t);
    };
    bool can_seed = false;
    {
      std::lock_guard<std::mutex> lock(board_mutex);
      can_seed = config.odometry.use_imu && (lis_imu_initialized || lis_sweeps < kLisStartSweeps);
    }
    if (can_seed)
      seed = [this](Time t) -> std::optional<vio::SeedState> {
        std::lock_guard<std::mutex> lock(board_mutex);
        if (!lis_bias || !lis_imu_initialized || lis_sweeps < kLisSeedMinSweeps) return std::nullopt;
        return lisSeedAt(imu_rate, t, *lis_bias);
      };
  }
  try {
    const vio::VisFrame f = vo->addFrame(frame, pose_at, seed);
    if (cb.vis_frame) cb.vis_frame(f);
  } catch (const std::invalid_argument& e) {  // wrong size or type, a stamp not after the previous frame's
    std::size_t n = 0;
    {
      std::lock_guard<std::mutex> lock(stats_mutex);
      n = ++stats.frames_bad;
    }
    if (n <= kShownDrops) warn(fmt::format("camera frame {} skipped: {}", frame.source, e.what()));
  }
}

// The LIS first (it still makes keyframes and depth sweeps), then the loop search of every keyframe and its last
// correction (applied here: the LIS thread is gone), then the VIS.
void System::Impl::stop() {
  stopped = true;
  lis_queue.close();
  if (lis_thread.joinable()) lis_thread.join();
  {
    std::lock_guard<std::mutex> lock(loop_mutex);
    loop_stop = true;
  }
  loop_wake.notify_all();
  if (loop_thread.joinable()) loop_thread.join();
  {
    std::lock_guard<std::mutex> lock(lis_state_mutex);
    applyCorrection();
  }
  vis_queue.close();
  if (vis_thread.joinable()) vis_thread.join();
  joined = true;
}

System::System(const SystemConfig& config, const Calibration& calibration, SystemCallbacks callbacks,
               std::shared_ptr<visual::KeypointDetector> detector)
    : impl_(std::make_unique<Impl>(config, calibration, std::move(callbacks), std::move(detector))) {
  Impl& m = *impl_;
  m.lis_thread = std::thread([&m] { m.lisLoop(); });
  if (m.loops) m.loop_thread = std::thread([&m] { m.loopLoop(); });
  if (m.vo) m.vis_thread = std::thread([&m] { m.visLoop(); });
}

System::~System() { shutdown(); }

void System::pushImu(const ImuSample& sample) {
  Impl& m = *impl_;
  if (m.stopped) return;
  {
    std::lock_guard<std::mutex> lock(m.stats_mutex);
    ++m.stats.imu_pushed;
  }
  m.onImu(sample);
  if (m.config.use_lidar) m.lis_queue.push(sample, false, 0);
  if (m.vo) m.vis_queue.push(sample, false, 0);
}

void System::pushSweep(LidarScan scan) {
  Impl& m = *impl_;
  if (m.stopped || !m.config.use_lidar) return;
  {
    std::lock_guard<std::mutex> lock(m.stats_mutex);
    ++m.stats.sweeps_pushed;
  }
  if (m.lis_queue.push(std::move(scan), true, static_cast<std::size_t>(m.config.live.sweep_queue)))
    m.countDrop(&SystemStats::sweeps_dropped, "the LIS", "sweep");
}

void System::pushFrame(CameraFrame frame) {
  Impl& m = *impl_;
  if (m.stopped || !m.vo) return;
  {
    std::lock_guard<std::mutex> lock(m.stats_mutex);
    ++m.stats.frames_pushed;
  }
  if (m.vis_queue.push(std::move(frame), true, static_cast<std::size_t>(m.config.live.frame_queue)))
    m.countDrop(&SystemStats::frames_dropped, "the VIS", "frame");
}

void System::shutdown() {
  if (!impl_->joined) impl_->stop();
}

SystemStats System::stats() const {
  std::lock_guard<std::mutex> lock(impl_->stats_mutex);
  return impl_->stats;
}

void System::inspect(const std::function<void(const LidarOdometry&, const LoopClosure*)>& f) const {
  std::lock_guard<std::mutex> lis_lock(impl_->lis_state_mutex);
  std::lock_guard<std::mutex> loop_lock(impl_->loop_state_mutex);
  f(impl_->lis, impl_->loops ? &impl_->loops->loopClosure() : nullptr);
}

const LidarOdometry& System::lis() const {
  if (!impl_->joined) throw std::logic_error("System::lis() before shutdown()");
  return impl_->lis;
}

const LoopClosure* System::loopClosure() const {
  if (!impl_->joined) throw std::logic_error("System::loopClosure() before shutdown()");
  return impl_->loops ? &impl_->loops->loopClosure() : nullptr;
}

const vio::VisualOdometry* System::vis() const {
  if (!impl_->joined) throw std::logic_error("System::vis() before shutdown()");
  return impl_->vo.get();
}

}  // namespace drover::pipeline
