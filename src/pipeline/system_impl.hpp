#pragma once
// System's internals (src/pipeline/system.cpp: construction, input, shutdown; system_stages.cpp: the threads'
// loops). Not installed: only those two files include it.
#include <fmt/format.h>

#include <atomic>
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
#include "pipeline/visual_yaw_history.hpp"
#include "pipeline/stream_clock.hpp"
#include "pipeline/system.hpp"

namespace drover::pipeline {
namespace system_internal {
constexpr Time kBoardSpan = 10'000'000'000;  // [ns] IMU-rate poses kept for the VIS's lookups
constexpr std::size_t kShownDrops = 10;      // drop warnings printed; then every hundredth

// The config, or std::invalid_argument naming the bad live key (before any member is built from it).
inline const SystemConfig& validated(const SystemConfig& c) {
  if (std::string e = c.live.validate(); !e.empty()) throw std::invalid_argument("live config: " + e);
  return c;
}

inline bool accepted(imu::SampleStatus s) {
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

}  // namespace system_internal

struct System::Impl {
  using VisItem = system_internal::VisItem;
  SystemConfig config;
  SystemCallbacks cb;
  LidarOdometry lis;
  std::unique_ptr<LoopWorker> loops;
  std::unique_ptr<VisualYawHistory> visual_yaw;  // the VIS thread adds, the loop thread asks (thread-safe)
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

  // The VIS's states for the LIS (VIS -> LIS fusion): pushed by the VIS thread, taken by the LIS thread before
  // each measurement. States that arrive after their sweep was fused are simply not used for it (late is late).
  std::mutex visual_mutex;
  std::vector<VisualState> visual_states;
  std::string vis_reset_request;  // the LIS asks the VIS thread to reset (ScanOutcome::vis_reset); visual_mutex
  VisualStateStream visual_stream;  // VIS thread only

  LiveQueue<Measurement> lis_queue;
  LiveQueue<VisItem> vis_queue;
  // Keyframes for the loop thread, and the newest correction for the LIS (a later one contains the earlier).
  std::mutex loop_mutex;
  std::condition_variable loop_wake;
  std::vector<KeyframeRecord> keyframes;
  bool loop_stop = false;
  std::optional<LoopCorrection> correction;
  std::atomic<bool> has_correction{false};

  StreamClock clocks;  // clock jumps and sensor gaps; after a jump all input is ignored
  std::size_t notices_shown = 0;  // the LIS's OdometryStats::notices passed on as warnings (LIS thread)

  mutable std::mutex stats_mutex;
  SystemStats stats;
  std::atomic<bool> stopped{false};
  bool joined = false;
  std::thread lis_thread, loop_thread, vis_thread;

  Impl(const SystemConfig& c, const Calibration& calibration, SystemCallbacks callbacks,
       std::shared_ptr<visual::KeypointDetector> detector)
      : config(system_internal::validated(c)),
        cb(std::move(callbacks)),
        lis(c.odometry, calibration),
        propagator(c.odometry.propagator),
        clocks(fromSeconds(c.live.clock_jump_s), fromSeconds(c.live.sensor_gap_s)) {
    if (c.odometry.loop.enabled) loops = std::make_unique<LoopWorker>(c.odometry.loopClosure(), c.odometry.local_map);
    if (c.vis && detector) {
      // Live, the detector runs in the tracker's worker thread (SuperPoint takes ~0.4 s a frame here): KLT tracks
      // every frame meanwhile. The replay keeps it synchronous, hence deterministic.
      vio::VisConfig vis = *c.vis;
      vis.tracker.async_detection = true;
      vo = std::make_unique<vio::VisualOdometry>(vis, calibration, c.odometry.preintegration, std::move(detector));
    }
    if (loops && vo && c.odometry.loop.visual_yaw_prior) {
      visual_yaw = std::make_unique<VisualYawHistory>(calibration.T_imu_lidar);
      loops->setVisualYawPrior(visual_yaw->prior());
    }
    lis.setKeyframeListener([this](const KeyframeRecord& k) { onKeyframe(k); }, loops != nullptr);
    if (vo || cb.deskewed_sweep)
      lis.setSweepListener([this](Time t, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& p) {
        if (cb.deskewed_sweep) cb.deskewed_sweep(t, T, p);
        if (vo) vis_queue.push(system_internal::DepthSweep{t, T, p}, false, 0);
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
    if (n <= system_internal::kShownDrops || n % 100 == 0)
      warn(fmt::format("live: {} fell behind: the oldest waiting {} dropped ({} so far)", stage, what, n));
  }

  bool admit(StreamClock::Stream stream, Time t);
  std::vector<std::string> takeNotices();
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

}  // namespace drover::pipeline
