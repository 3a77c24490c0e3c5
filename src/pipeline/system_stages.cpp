// The live system's threads: the IMU front on the pushing thread, the LIS, the loop search and the VIS (see
// system.hpp for what each does and how they talk).
#include <chrono>

#include "pipeline/system_impl.hpp"

namespace drover::pipeline {

using system_internal::accepted;
using system_internal::DepthSweep;
using system_internal::kBoardSpan;
using system_internal::kShownDrops;
using system_internal::WorldCorrection;

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
    std::vector<std::string> notices;
    std::vector<VisualState> visual;
    {
      std::lock_guard<std::mutex> lock(visual_mutex);
      visual.swap(visual_states);
    }
    {
      std::lock_guard<std::mutex> lock(lis_state_mutex);
      applyCorrection();
      for (const VisualState& v : visual) lis.addVisualState(v);
      outcomes = lis.process(*m);
      notices = takeNotices();
    }
    for (const ScanOutcome& o : outcomes)
      if (!o.vis_reset.empty()) {
        std::lock_guard<std::mutex> lock(visual_mutex);
        vis_reset_request = o.vis_reset;
      }
    for (const std::string& n : notices) warn("LIS: " + n);
    const bool done_sweep = !outcomes.empty();
    publish(std::move(outcomes));
    // Idle until the next sweep: the local map for it is built now, not in its latency.
    if (done_sweep && lis_queue.droppableWaiting() == 0) {
      std::lock_guard<std::mutex> lock(lis_state_mutex);
      lis.prepareMap();
    }
  }
  std::vector<ScanOutcome> outcomes;
  std::vector<std::string> notices;
  {
    std::lock_guard<std::mutex> lock(lis_state_mutex);
    applyCorrection();
    outcomes = lis.finish();
    notices = takeNotices();
  }
  for (const std::string& n : notices) warn("LIS: " + n);
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
  Eigen::Isometry3d T_new_old;
  try {
    T_new_old = lis.applyLoopCorrection(*c);
  } catch (const std::exception& e) {  // a correction the LIS refuses is dropped, never a crash of the live system
    warn(fmt::format("live: loop correction of keyframe {} not applied: {}", c->event.query, e.what()));
    return;
  }
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
      try {
        std::lock_guard<std::mutex> lock(loop_state_mutex);
        c = loops->add(k);
      } catch (const std::exception& e) {  // the search goes on with the next keyframe; the LIS never stops
        warn(fmt::format("live: loop search at keyframe {} failed: {}", k.index, e.what()));
        continue;
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
  std::string reset_by_lis;
  {
    std::lock_guard<std::mutex> lock(visual_mutex);
    reset_by_lis.swap(vis_reset_request);
  }
  if (!reset_by_lis.empty() && vo->estimator().initialized()) vo->reset();
  else reset_by_lis.clear();
  try {
    vio::VisFrame f = vo->addFrame(frame, pose_at, seed);
    if (!reset_by_lis.empty() && !f.estimate.reset) {  // reported as the VIS's own resets are (RunVis::record)
      f.estimate.reset = true;
      f.estimate.event = "reset by the LIS: " + reset_by_lis;
    }
    if (const std::optional<VisualState> v = visual_stream.onFrame(f.estimate); v && config.use_lidar) {
      if (visual_yaw) visual_yaw->add(*v);
      std::lock_guard<std::mutex> lock(visual_mutex);
      visual_states.push_back(*v);
    }
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

}  // namespace drover::pipeline
