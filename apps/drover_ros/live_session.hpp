#pragma once
// The live Drover behind the ROS node, free of ROS: a pipeline::System built from a platform config (as `drover run
// --config` reads it), its outputs in plain types for the node to publish, the map and keyframe path read while it
// runs, and the run folder that `drover run` writes (the node's ~save service and ~save_on_exit).
//
// This header is C++17 on purpose: Debian 12's ROS1 message headers do not compile as C++20 (they use
// std::allocator<T>::rebind, removed in C++20), so the ROS side is built as C++17 and reaches Drover's C++20 core
// only through this class (live_session.cpp is C++20 and includes no ROS header).
//
// Frames: the world frame is the LIS's (gravity-aligned at the IMU's initialisation); the body is the IMU when the
// platform loads one, else the lidar (as drover run's trajectory.tum for a dataset with an IMU).
#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "io/dataset.hpp"
#include "types/trajectory.hpp"

namespace drover::live {

struct LiveOptions {
  std::string config;           // platform YAML: dataset: (topics, sensors), calibration:, odometry:, visual:, vio:
  bool use_camera = true;       // run the VIS when the platform loads images, has intrinsics and an IMU
  bool use_loop = true;         // loop closure (when the config's odometry.loop.enabled also says so)
  std::size_t sweep_queue = 2;  // [sweeps] waiting for the LIS at most (pipeline::LiveConfig)
  // A relative SuperPoint weights path in the config that neither the working directory nor the config's folder
  // holds is looked for here (cli::loadVisSetup): the launch file gives the repository, the folder drover run's
  // shipped paths are written for. Empty: not looked for.
  std::string working_dir;
};

// The body's pose (and velocity when known) in the world frame at t.
struct BodyPose {
  Time t = 0;  // [ns]
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  // [m/s], valid when has_velocity
  bool has_velocity = false;
};

// One sweep the LIS processed.
struct SweepResult {
  BodyPose pose;  // at the sweep's start (LidarScan::t on the IMU clock)
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();
  bool keyframe = false, degenerate = false;
  std::string warning, note;  // one line each, empty when none
};

// An accepted loop between two keyframes (indices into LiveView::keyframes).
struct LoopLink {
  std::size_t query = 0, candidate = 0;
  Time t_query = 0, t_candidate = 0;  // [ns]
};

// What the node shows while the system runs: keyframe poses as they are now (loop corrections included).
struct LiveView {
  Trajectory keyframes;                  // T_world_body of every keyframe, in order
  std::vector<LoopLink> loops;           // every accepted loop
  std::vector<Eigen::Vector3f> map;      // [m] world frame: the keyframes' deskewed clouds, voxel-downsampled
};

struct LiveCallbacks {  // called from the System's threads (see pipeline/system.hpp); must be quick
  std::function<void(const BodyPose&)> imu_odometry;  // the IMU's pose at every IMU sample once initialised
  std::function<void(const SweepResult&)> sweep;
  // Before that sweep's `sweep`: its deskewed, downsampled points [m] in the lidar frame at the sweep's start (t on
  // the IMU clock [ns]) and T_world_lidar there.
  std::function<void(Time t, const Eigen::Isometry3d& T_world_lidar, const std::vector<Eigen::Vector3f>& points)>
      deskewed_sweep;
  std::function<void(const LoopLink&)> loop;
  std::function<void(const std::string&)> warning;
  // The session restarted by itself (a sensor clock jumped back: a restarted recording, a reset clock): the map and
  // trajectory are empty again, as after reset(). Called on the pushing thread, after the restart.
  std::function<void(const std::string& why)> restarted;
};

class LiveSession {
 public:
  // Reads the platform config and starts the System. Throws io::IoError (file, line, key) for a bad config and
  // std::invalid_argument for a platform the node cannot run (no lidar).
  LiveSession(const LiveOptions& options, LiveCallbacks callbacks);
  ~LiveSession();
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  const io::DatasetOptions& platform() const;  // topics, which sensors to use, calibration
  bool visRuns() const;                          // the VIS runs beside the LIS
  const std::string& visDetector() const;        // its detector ("superpoint", "shi-tomasi (SuperPoint ...)")
  const std::string& bodyFrame() const;          // "imu" or "lidar"

  // Thread-safe; one thread per sensor keeps each stream in order. Ignored after shutdown(). When a stream's clock
  // jumps back (pipeline::LiveConfig::clock_jump_s) the session first restarts as reset() does and calls
  // LiveCallbacks::restarted; the measurement then goes into the fresh System.
  void pushImu(const ImuSample& sample);
  void pushSweep(LidarScan scan);
  void pushFrame(CameraFrame frame);
  // Counts a message the caller could not decode (report.json's counts.measurements_dropped) and warns (the first
  // ten, then every hundredth).
  void dropped(const std::string& notice);

  // The keyframe poses and loops now, and the map when map_leaf > 0 [m] (voxel leaf; assembled outside the
  // System's locks, the LIS pauses only to copy the poses).
  LiveView view(float map_leaf) const;

  // Writes drover run's run folder into `dir` (staged as dir.partial, replacing only an earlier run folder): the
  // LIS pauses while the files are written. `end` is report.json's end reason. Returns a one-line summary. Throws
  // io::IoError for an unusable folder and std::invalid_argument when no sweep has produced a pose yet.
  std::string save(const std::string& dir, const std::string& end);

  // Drains the running System and starts a fresh one: empty map and trajectory (the config is read again).
  void reset();
  // Stops the input and lets every stage finish what is queued (System::shutdown). Idempotent.
  void shutdown();
  // One line: sweeps in/processed/dropped, keyframes, loops.
  std::string summary() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::live
