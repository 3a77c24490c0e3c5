#pragma once
// The live Drover: a streaming system for a robot (and `drover run --realtime`, and the ROS node). Threads as
// LIO-SAM and LVI-SAM have them:
//   - the caller's threads push IMU samples, lidar sweeps and camera frames, each with its sensor stamp;
//   - IMU-rate odometry is propagated on the thread that pushes the IMU sample, from the LIS's newest fused state
//     (LIO-SAM's imuPreintegration), and published at once;
//   - the LIS (LidarOdometry) runs in its own thread; its input queue keeps every IMU sample and at most
//     live.sweep_queue sweeps (the oldest waiting sweep is dropped, with a counted warning, when the CPU falls
//     behind);
//   - loop closure runs in its own thread (LoopWorker), waking live.loop_rate_hz times a second to search every
//     keyframe made since, in order (so the accepted loops are the replay's); the LIS applies a correction before
//     its next measurement (LIO-SAM's correctPoses);
//   - the VIS (vio::VisualOdometry) runs in its own thread with at most live.frame_queue frames waiting, fed the IMU,
//     the LIS's deskewed sweeps (lidar depth) and its IMU-rate poses and state (initialisation); its detector runs
//     asynchronously in the tracker's worker thread (KLT tracks every frame while SuperPoint works).
// Bad input is warned about and counted, never a crash or a hang: a sweep or frame out of order is skipped by its
// stage (the LIS's notices are passed on as warnings), a sensor that stops and restarts is reported (the IMU bridges
// a lidar gap; an IMU gap is bridged by the lidar alone), a burst drops the oldest waiting sweeps, and a clock that
// jumps back stops the System (see SystemCallbacks::clock_jump).
// Outputs are callbacks, each called from the thread that produced it (a callback must be quick and thread-safe
// with respect to the caller's own data). shutdown() stops the input, lets every stage finish what is queued, and
// joins the threads; the destructor does it if the caller did not.
// The deterministic replay (`drover run`, the tests) drives the same LidarOdometry and VisualOdometry in time order
// on one thread; System is for live use.
#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pipeline/lidar_odometry.hpp"
#include "types/calibration.hpp"
#include "types/camera.hpp"
#include "types/imu.hpp"
#include "types/lidar.hpp"
#include "vio/visual_odometry.hpp"

namespace drover::pipeline {

struct LiveConfig {
  int sweep_queue = 2;          // [sweeps] waiting for the LIS at most; a new one then drops the oldest
  int frame_queue = 2;          // [frames] waiting for the VIS at most; likewise
  double loop_rate_hz = 1.0;    // [Hz] how often the loop thread searches the keyframes made since (LIO-SAM: 1)
  // [s] a stamp this far before its stream's previous stamp is a clock jump (a restarted bag, a clock reset); a
  // smaller step back is an out-of-order message, skipped by the stage that gets it
  double clock_jump_s = 1.0;
  // [s] a lidar or camera silent this long is reported when it speaks again (an IMU gap the LIS reports itself)
  double sensor_gap_s = 1.0;
  std::string validate() const;  // empty when valid
};

struct SystemConfig {
  OdometryConfig odometry;
  std::optional<vio::VisConfig> vis;  // the VIS runs when set (and a detector is given)
  bool use_lidar = true;              // false: the VIS alone (camera + IMU); pushed sweeps are ignored
  LiveConfig live;
};

// One IMU-rate odometry output: the IMU's pose and velocity at a sample's stamp.
struct ImuOdometry {
  Time t = 0;  // [ns] the IMU sample's stamp
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  // [m/s]
};

struct SystemCallbacks {
  std::function<void(const ImuOdometry&)> imu_odometry;  // pushing thread; every accepted sample once initialised
  std::function<void(const ScanOutcome&)> sweep;         // LIS thread; every processed sweep
  std::function<void(const KeyframeRecord&)> keyframe;   // LIS thread; every keyframe (map update)
  // LIS thread, before that sweep's `sweep` callback: its deskewed, downsampled points in the lidar frame at the
  // sweep's start and T_world_lidar there (the ROS node's ~cloud).
  LidarOdometry::SweepListener deskewed_sweep;
  std::function<void(const LoopCorrection&)> loop;       // loop thread; every accepted loop
  std::function<void(const vio::VisFrame&)> vis_frame;   // VIS thread; every frame the VIS took
  std::function<void(const std::string&)> warning;       // any thread: dropped input, skipped frames
  // Pushing thread: a stream's clock jumped back (stream "imu", "lidar" or "camera"; stamps [ns]). The System then
  // ignores all input (it cannot tell a restarted recording from a robot that moved meanwhile): the owner starts a
  // new one (drover_ros does, as its ~reset). Called once, for the first stream that jumped.
  std::function<void(const std::string& stream, Time previous, Time now)> clock_jump;
};

struct SystemStats {
  std::size_t imu_pushed = 0, sweeps_pushed = 0, frames_pushed = 0;
  std::size_t sweeps_dropped = 0, frames_dropped = 0;  // dropped from full queues (the CPU fell behind)
  std::size_t loops_applied = 0;                       // loop corrections the LIS applied
  std::size_t frames_bad = 0;                          // frames the VIS rejected (wrong size, stamp order)
  std::size_t clock_jumps = 0;                         // 0 or 1: input is ignored after the first
  std::size_t ignored_after_jump = 0;                  // measurements pushed after the clock jumped back
  std::size_t sensor_restarts = 0;                     // a lidar or camera silent > live.sensor_gap_s spoke again
};

class System {
 public:
  // Starts the threads. Throws std::invalid_argument on an invalid config; detector is needed when config.vis is
  // set (else the VIS does not run).
  System(const SystemConfig& config, const Calibration& calibration, SystemCallbacks callbacks,
         std::shared_ptr<visual::KeypointDetector> detector = nullptr);
  ~System();
  System(const System&) = delete;
  System& operator=(const System&) = delete;

  // Thread-safe; ignored after shutdown().
  void pushImu(const ImuSample& sample);
  void pushSweep(LidarScan scan);
  void pushFrame(CameraFrame frame);

  // Stops the input, processes everything queued (the LIS's waiting sweeps, the loop search of every keyframe, a
  // last loop correction), joins the threads. Idempotent.
  void shutdown();

  SystemStats stats() const;
  // [bytes] the keyframe clouds held by the LIS's map and by the loop thread's store (the memory that grows with the
  // map; each keyframe is in both). Thread-safe, pauses both as inspect() does.
  struct KeyframeMemory {
    std::size_t lis = 0, loop = 0;
  };
  KeyframeMemory keyframeMemory() const;
  // Calls f with the LIS and the loop search's LoopClosure (nullptr when loop closure is off) while neither works:
  // between two measurements of the LIS and two keyframes of the loop search, which wait meanwhile (input keeps
  // queueing; a full sweep queue drops its oldest as usual, so f should be quick). For reading the state while the
  // system runs (the ROS node's map, path and save service); after shutdown() it simply calls f.
  void inspect(const std::function<void(const LidarOdometry& lis, const LoopClosure* loops)>& f) const;
  // After shutdown() only (the stages are idle then): for writing the run's files.
  const LidarOdometry& lis() const;
  const LoopClosure* loopClosure() const;       // the loop thread's; nullptr when loop closure is off
  const vio::VisualOdometry* vis() const;       // nullptr without the VIS

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::pipeline
