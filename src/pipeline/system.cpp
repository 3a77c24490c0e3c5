#include "pipeline/system.hpp"

#include <fmt/format.h>
#include <pthread.h>

#include <cmath>

#include "pipeline/system_impl.hpp"

namespace drover::pipeline {

std::string LiveConfig::validate() const {
  if (sweep_queue < 1) return "live.sweep_queue must be >= 1";
  if (frame_queue < 1) return "live.frame_queue must be >= 1";
  if (!std::isfinite(loop_rate_hz) || loop_rate_hz <= 0) return "live.loop_rate_hz must be > 0";
  if (!std::isfinite(clock_jump_s) || clock_jump_s <= 0) return "live.clock_jump_s must be > 0";
  if (!std::isfinite(sensor_gap_s) || sensor_gap_s <= 0) return "live.sensor_gap_s must be > 0";
  return "";
}

// False when the measurement is to be ignored: the clock jumped back, now or before. Reports a lidar or camera
// that restarts after a silence.
bool System::Impl::admit(StreamClock::Stream stream, Time t) {
  const StreamClock::Verdict v = clocks.check(stream, t);
  switch (v.kind) {
    case StreamClock::Kind::kAdmit: return true;
    case StreamClock::Kind::kRestart: {
      {
        std::lock_guard<std::mutex> lock(stats_mutex);
        ++stats.sensor_restarts;
      }
      warn(fmt::format("live: the {} was silent for {:.2f} s ({:.3f} s to {:.3f} s) and is back{}",
                       StreamClock::name(stream), toSeconds(t - v.previous), toSeconds(v.previous), toSeconds(t),
                       stream == StreamClock::Stream::kLidar ? "; the IMU bridged the gap" : ""));
      return true;
    }
    case StreamClock::Kind::kJump: {
      {
        std::lock_guard<std::mutex> lock(stats_mutex);
        stats.clock_jumps = 1;
        ++stats.ignored_after_jump;
      }
      warn(fmt::format("live: the {} clock jumped back {:.3f} s ({:.6f} s after {:.6f} s): all input is ignored "
                       "from now on (a restarted recording or a reset clock cannot be told from motion); start a new "
                       "system", StreamClock::name(stream), toSeconds(v.previous - t), toSeconds(t),
                       toSeconds(v.previous)));
      if (cb.clock_jump) cb.clock_jump(StreamClock::name(stream), v.previous, t);
      return false;
    }
    case StreamClock::Kind::kIgnore: break;
  }
  std::lock_guard<std::mutex> lock(stats_mutex);
  ++stats.ignored_after_jump;
  return false;
}

// The LIS's new notices (a skipped sweep, an IMU gap or spike): warnings live, as drover run prints them.
std::vector<std::string> System::Impl::takeNotices() {
  const std::vector<std::string>& all = lis.stats().notices;
  std::vector<std::string> out(all.begin() + static_cast<std::ptrdiff_t>(std::min(notices_shown, all.size())),
                               all.end());
  notices_shown = all.size();
  return out;
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
  // Named, so that `top -H` on the robot says which stage takes the CPU.
  m.lis_thread = std::thread([&m] {
    pthread_setname_np(pthread_self(), "drover-lis");
    m.lisLoop();
  });
  if (m.loops)
    m.loop_thread = std::thread([&m] {
      pthread_setname_np(pthread_self(), "drover-loop");
      m.loopLoop();
    });
  if (m.vo)
    m.vis_thread = std::thread([&m] {
      pthread_setname_np(pthread_self(), "drover-vis");
      m.visLoop();
    });
}

System::~System() { shutdown(); }

void System::pushImu(const ImuSample& sample) {
  Impl& m = *impl_;
  if (m.stopped) return;
  {
    std::lock_guard<std::mutex> lock(m.stats_mutex);
    ++m.stats.imu_pushed;
  }
  if (!m.admit(StreamClock::Stream::kImu, sample.t)) return;
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
  if (!m.admit(StreamClock::Stream::kLidar, scan.t)) return;
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
  if (!m.admit(StreamClock::Stream::kCamera, frame.t)) return;
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

System::KeyframeMemory System::keyframeMemory() const {
  std::lock_guard<std::mutex> lis_lock(impl_->lis_state_mutex);
  std::lock_guard<std::mutex> loop_lock(impl_->loop_state_mutex);
  return {impl_->lis.keyframeBytes(), impl_->loops ? impl_->loops->keyframeBytes() : 0};
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
