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
  std::function<void(const LoopCorrection&)> loop;       // loop thread; every accepted loop
  std::function<void(const vio::VisFrame&)> vis_frame;   // VIS thread; every frame the VIS took
  std::function<void(const std::string&)> warning;       // any thread: dropped input, skipped frames
};

struct SystemStats {
  std::size_t imu_pushed = 0, sweeps_pushed = 0, frames_pushed = 0;
  std::size_t sweeps_dropped = 0, frames_dropped = 0;  // dropped from full queues (the CPU fell behind)
  std::size_t loops_applied = 0;                       // loop corrections the LIS applied
  std::size_t frames_bad = 0;                          // frames the VIS rejected (wrong size, stamp order)
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
