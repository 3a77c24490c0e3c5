#pragma once
// The runners of bench_memory_hour: what drives the System (live threads) or LidarOdometry (replay, in line) lap
// after lap, and the per-lap row each fills (counts and memory). Included by bench_memory_hour.cpp alone.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "apps/drover/run_record.hpp"
#include "apps/drover/run_vis.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/loop_worker.hpp"
#include "pipeline/system.hpp"

namespace drover::bench {

struct Lap {
  int lap = 0;
  double data_s = 0, wall_s = 0;
  long rss_kb = 0, peak_kb = 0;
  std::size_t heap_used = 0, heap_free = 0;  // [bytes] malloc's blocks in use, and held free (all arenas, mallinfo2)
  std::size_t sweeps = 0, keyframes = 0, dropped = 0, loops = 0;
  std::size_t frames = 0, frames_dropped = 0, vis_estimates = 0;  // camera frames the VIS took, dropped, estimated
  std::size_t kf_lis = 0, kf_loop = 0;  // [bytes] keyframe clouds held by the LIS, and by the loop thread alone
  std::size_t retired = 0;               // keyframes whose clouds were freed (a newer one stands for the place)
  std::size_t cache = 0, descriptors = 0;  // [bytes] the local map's world-frame cache, the Scan Context database
  pipeline::LoopStats loop_stats;        // cumulative
  std::size_t graph_refusals = 0;        // verified loops the pose graph failed to solve (cumulative)
  double graph_iterations = 0;           // mean iterations of the re-solves of this lap's accepted loops
  double max_rotation = 0;               // [rad] largest implied rotation of this lap's accepted loops
  std::size_t graph_nodes = 0;           // pose-graph nodes (keyframes less those merged on retirement)
};

// The loop closure's counts: loops the pose graph refused (verified, within the drift budget, rolled back because
// the solve failed), and for the events since `first_event` (this lap) the solves' mean iterations and the largest
// rotation a loop implied.
inline void loopCounts(const pipeline::LoopClosure& loops, std::size_t first_event, Lap& row) {
  row.loop_stats = loops.stats();
  row.graph_nodes = loops.graphNodes();
  std::size_t solves = 0, iterations = 0;
  const std::vector<pipeline::LoopEvent>& events = loops.events();
  for (std::size_t i = 0; i < events.size(); ++i) {
    const pipeline::LoopEvent& e = events[i];
    if (e.verification.reason.rfind("rejected: pose graph failed", 0) == 0) ++row.graph_refusals;
    if (loops.eventsDropped() + i < first_event || !e.verification.accepted) continue;
    ++solves;
    iterations += static_cast<std::size_t>(e.graph_iterations);
    row.max_rotation = std::max(row.max_rotation, e.implied_rotation);
  }
  row.graph_iterations = solves ? static_cast<double>(iterations) / static_cast<double>(solves) : 0.0;
}


// The System (live threads) or LidarOdometry (replay, in line) fed measurement by measurement.
class Runner {
 public:
  virtual ~Runner() = default;
  virtual void push(Measurement&& m) = 0;
  virtual void fill(Lap& row) = 0;  // counts and memory so far
  virtual void finish() = 0;
  virtual const pipeline::LoopClosure* loops() const { return nullptr; }
  virtual const lidar::LocalMap* keyframes() const { return nullptr; }
  cli::RunRecord record;
};

class LiveRunner : public Runner {
 public:
  // With vis: the VIS in its own thread (camera frames pushed with pushFrame), its estimate streamed to vis_tum.
  LiveRunner(const pipeline::OdometryConfig& odometry, const Calibration& calibration, double loop_hz,
             const cli::VisSetup* vis = nullptr, const std::string& vis_tum = {}) {
    pipeline::SystemCallbacks cb;
    if (vis != nullptr) {
      vis_tum_ = std::make_unique<io::TumStream>(vis_tum);
      cb.vis_frame = [this](const vio::VisFrame& f) {
        if (f.estimate.initialized) {
          std::lock_guard<std::mutex> lock(record_mutex_);
          vis_tum_->add({f.estimate.t, f.estimate.T_world_imu});
          ++vis_estimates_;
        }
        ++frames_taken_;
      };
    }
    cb.imu_odometry = [this](const pipeline::ImuOdometry& o) { record.imu_rate->add(o.t, o.T_world_imu); };
    cb.sweep = [this](const pipeline::ScanOutcome& s) {
      {
        std::lock_guard<std::mutex> lock(record_mutex_);
        record.add(s);
      }
      ++processed_;
    };
    pipeline::SystemConfig config;
    config.odometry = odometry;
    config.live.sweep_queue = 4;
    config.live.loop_rate_hz = loop_hz;
    if (vis != nullptr) config.vis = vis->config;
    system_ = std::make_unique<pipeline::System>(config, calibration, cb, vis ? vis->detector : nullptr);
  }
  void push(Measurement&& m) override {
    if (auto* imu = std::get_if<ImuSample>(&m)) {
      system_->pushImu(*imu);
    } else if (auto* scan = std::get_if<LidarScan>(&m)) {
      // As fast as it keeps up: the next sweep goes in once the one before it is processed.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
      while (processed_.load() + system_->stats().sweeps_dropped + 1 < pushed_ &&
             std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      ++pushed_;
      system_->pushSweep(std::move(*scan));
    } else if (auto* frame = std::get_if<CameraFrame>(&m)) {
      // Likewise for the VIS: a frame goes in once the one before it is taken (or dropped, or refused).
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(1000);
      while (framesDone() + 1 < frames_pushed_ && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      ++frames_pushed_;
      system_->pushFrame(std::move(*frame));
    }
  }
  void fill(Lap& row) override {
    row.sweeps = processed_.load();
    row.dropped = system_->stats().sweeps_dropped;
    row.loops = system_->stats().loops_applied;
    row.frames = frames_taken_.load();
    row.frames_dropped = system_->stats().frames_dropped;
    row.vis_estimates = vis_estimates_.load();
    const pipeline::System::KeyframeMemory kf = system_->keyframeMemory();
    row.kf_lis = kf.lis;
    row.kf_loop = kf.loop;
    system_->inspect([&](const pipeline::LidarOdometry& lis, const pipeline::LoopClosure* loops) {
      row.keyframes = lis.stats().keyframes;
      row.retired = lis.stats().keyframes_retired;
      row.cache = lis.keyframeMap().cacheBytes();
      if (loops) {
        loopCounts(*loops, events_seen_, row);
        events_seen_ = loops->eventsDropped() + loops->events().size();
        row.descriptors = loops->descriptorBytes();
      }
    });
  }
  void finish() override {
    system_->shutdown();
    if (vis_tum_) vis_tum_->close();
  }

 private:
  // Frames the VIS is done with: taken, dropped from its queue, or refused.
  std::size_t framesDone() const {
    const pipeline::SystemStats s = system_->stats();
    return frames_taken_.load() + s.frames_dropped + s.frames_bad;
  }
  std::unique_ptr<pipeline::System> system_;
  std::unique_ptr<io::TumStream> vis_tum_;
  std::atomic<std::size_t> frames_taken_{0}, vis_estimates_{0};
  std::size_t frames_pushed_ = 0;
  std::atomic<std::size_t> processed_{0};
  std::size_t pushed_ = 0, events_seen_ = 0;
  std::mutex record_mutex_;
};

// LidarOdometry fed in line (replay and delayed modes): what both count.
class InlineRunner : public Runner {
 public:
  InlineRunner(const pipeline::OdometryConfig& odometry, const Calibration& calibration)
      : lis_(odometry, calibration) {
    lis_.setImuRateListener([this](const StampedPose& p) { record.imu_rate->add(p.t, p.T_world_body); });
  }
  void finish() override {
    for (const pipeline::ScanOutcome& s : lis_.finish()) record.add(s);
  }
  const lidar::LocalMap* keyframes() const override { return &lis_.keyframeMap(); }

 protected:
  void process(const Measurement& m) {
    for (const pipeline::ScanOutcome& s : lis_.process(m)) {
      record.add(s);
      ++processed_;
    }
  }
  void fillFrom(const pipeline::LoopClosure& loops, Lap& row) {
    row.sweeps = processed_;
    row.loops = lis_.stats().loop_times.size();
    row.keyframes = lis_.stats().keyframes;
    row.kf_lis = lis_.keyframeBytes();
    row.retired = lis_.stats().keyframes_retired;
    row.cache = lis_.keyframeMap().cacheBytes();
    row.descriptors = loops.descriptorBytes();
    loopCounts(loops, events_seen_, row);
    events_seen_ = loops.eventsDropped() + loops.events().size();
  }
  pipeline::LidarOdometry lis_;

 private:
  std::size_t processed_ = 0, events_seen_ = 0;
};

class ReplayRunner : public InlineRunner {
 public:
  using InlineRunner::InlineRunner;
  void push(Measurement&& m) override { process(m); }
  void fill(Lap& row) override { fillFrom(lis_.loopClosure(), row); }
  const pipeline::LoopClosure* loops() const override { return &lis_.loopClosure(); }
};

// LidarOdometry with its loop closure outside, in line: keyframes searched by a LoopWorker in batches every
// `period` of data time, corrections applied before the next sweep.
class DelayedRunner : public InlineRunner {
 public:
  DelayedRunner(const pipeline::OdometryConfig& odometry, const Calibration& calibration, double period_s)
      : InlineRunner(odometry, calibration),
        worker_(odometry.loopClosure(), odometry.local_map),
        period_(fromSeconds(period_s)) {
    lis_.setKeyframeListener([this](const pipeline::KeyframeRecord& k) { pending_.push_back(k); }, true);
  }
  void push(Measurement&& m) override {
    if (const auto* scan = std::get_if<LidarScan>(&m)) {
      if (scan->t >= next_batch_) {
        next_batch_ = scan->t + period_;
        for (const pipeline::KeyframeRecord& k : pending_)
          if (std::optional<pipeline::LoopCorrection> c = worker_.add(k)) correction_ = std::move(c);
        pending_.clear();
      }
      if (correction_) {
        lis_.applyLoopCorrection(*correction_);
        correction_.reset();
      }
    }
    process(m);
  }
  void fill(Lap& row) override {
    fillFrom(worker_.loopClosure(), row);
    row.kf_loop = worker_.keyframeBytes();
  }
  const pipeline::LoopClosure* loops() const override { return &worker_.loopClosure(); }

 private:
  pipeline::LoopWorker worker_;
  Time period_ = 0, next_batch_ = 0;
  std::vector<pipeline::KeyframeRecord> pending_;
  std::optional<pipeline::LoopCorrection> correction_;
};


}  // namespace drover::bench
