#pragma once
// The lidar-inertial odometry (LIS) driven measurement by measurement, in time order, single-threaded: the
// deterministic replay that `drover run` and the system tests use. Per lidar sweep (LIO-SAM's chain):
//   sanitize -> ring/time inference (when the lidar gives none) -> deskew (IMU propagation, or a constant-velocity
//   model without an IMU) -> LOAM features -> initial guess (IMU prediction or constant velocity) -> scan-to-local-
//   map matching -> fixed-lag smoother (IMU preintegration + lidar pose factors; velocity and biases) -> keyframe.
// IMU samples go to the propagator; camera frames are ignored by the LIS. Every bad input (non-finite points,
// empty scans, stamps going backwards or repeating, IMU gaps and spikes, a diverging smoother) is handled with a
// counted warning, never a crash: see OdometryStats.
#include <Eigen/Geometry>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "imu/initializer.hpp"
#include "imu/preintegration.hpp"
#include "imu/propagator.hpp"
#include "lidar/feature_set.hpp"
#include "pipeline/loop_closure.hpp"
#include "pipeline/odometry_config.hpp"
#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "types/trajectory.hpp"

namespace drover::pipeline {

// Wall time of each stage for one sweep [ms].
struct StageTimes {
  double preprocess = 0, deskew = 0, features = 0, map = 0, match = 0, smoother = 0, loop = 0, total = 0;
};

// What happened to one sweep.
struct ScanOutcome {
  Time t = 0;                                                       // [ns] sweep start (the pose's time)
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();  // estimate at t
  bool keyframe = false;
  bool imu_used = false;          // deskew and guess came from the IMU propagation
  bool vis_guess = false;         // the matcher's guess was the VIS's motion since the previous sweep
  bool vis_factor = false;        // the VIS's motion entered the IMU smoother as a relative-pose factor
  std::string vis_unused;         // why not, while a VIS runs (empty when it was used or none runs)
  std::string vis_reset;          // the LIS asks the VIS to reset, and why (vis_fusion.reset_after); else empty
  std::string match_status;       // lidar::toString(MatchStatus), "first" for the first sweep
  std::string match_reason;       // the matcher's one-line reason
  bool converged = false;
  bool match_usable = false;      // converged or stopped at the iteration limit (else the pose is a prediction)
  bool degenerate = false;
  int degenerate_count = 0;       // degenerate directions of the match
  std::vector<Eigen::Matrix<double, 6, 1>> degenerate_directions;  // unit, lidar tangent [rho; phi]
  double min_eigenvalue = 0;      // [-] smallest eigenvalue of the match's J^T J (matcher.degeneracy_threshold's units)
  int iterations = 0;
  double fitness = 0;             // [m] RMS point-to-feature distance
  int edge_inliers = 0, plane_inliers = 0;
  std::size_t points = 0, edges = 0, planes = 0;  // valid points in, features out
  bool reset = false;             // the smoother diverged and was reset at this sweep
  // The smoother's newest state after this sweep (IMU mode, when it ran): the IMU's velocity in the world frame
  // [m/s] and the biases in the IMU frame, gyro [rad/s] and accelerometer [m/s^2].
  bool has_imu_state = false;
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero(), gyro_bias = Eigen::Vector3d::Zero(),
                  acc_bias = Eigen::Vector3d::Zero();
  bool loop_closed = false;       // this sweep's keyframe closed a loop: the trajectory so far was corrected
  Eigen::Isometry3d T_new_old = Eigen::Isometry3d::Identity();  // with loop_closed: how the newest keyframe moved
  std::string warning;            // one line when something was off with this sweep
  std::string note;               // one line of news (a loop closed), not a problem
  StageTimes ms;
};

struct OdometryStats {
  std::size_t scans_in = 0;              // sweeps received
  std::size_t scans_processed = 0;       // sweeps that produced a pose
  std::size_t scans_skipped_empty = 0;   // too few valid points to match
  std::size_t scans_skipped_time = 0;    // stamp not after the previous sweep's (duplicate or backwards)
  std::size_t points_dropped = 0;        // non-finite or out-of-range points removed (by the reader or sanitize)
  std::size_t points_nonfinite = 0;      // of which NaN/inf (a warning on each sweep that had any)
  std::size_t keyframes = 0;
  std::size_t keyframes_retired = 0;     // clouds freed: a newer keyframe stands for the place (retire_radius)
  std::size_t degenerate_scans = 0;
  std::size_t not_converged = 0;         // matches that stopped without converging (pose kept from the guess)
  std::size_t smoother_resets = 0;
  std::size_t imu_scans = 0;             // sweeps deskewed and predicted with the IMU
  std::size_t vis_guess_scans = 0;       // sweeps whose matcher guess was the VIS's motion
  std::size_t vis_factor_scans = 0;      // sweeps whose smoother update had the VIS's motion as a factor
  std::size_t vis_resets_requested = 0;  // sweeps that asked the VIS to reset (ScanOutcome::vis_reset)
  bool imu_initialized = false;
  std::string imu_init;                  // how the IMU was initialised (or why not)
  imu::ImuStreamStats imu;
  std::vector<Time> degenerate_times;    // [ns] sweep times of degenerate matches
  std::vector<Time> reset_times;         // [ns] sweep times of smoother resets
  std::vector<Time> map_restart_times;   // [ns] sweeps where a long degenerate stretch restarted the local map
  std::vector<Time> loop_times;          // [ns] sweeps whose keyframe closed a loop (see loopClosure().events())
  // One line per skipped sweep (the first kMaxNotices; the counters above count them all), for the caller to show.
  static constexpr std::size_t kMaxNotices = 200;
  std::vector<std::string> notices;
};

// A keyframe as the LIS made it: for loop closure in another thread (pipeline::LoopWorker) and map updates.
struct KeyframeRecord {
  std::size_t index = 0;                                               // in the LIS's keyframe map
  Time t = 0;                                                          // [ns]
  std::shared_ptr<const lidar::FeatureSet> features;  // lidar frame, the LIS map's downsampled clouds (shared)
  Eigen::Isometry3d T_world_lidar = Eigen::Isometry3d::Identity();     // the LIS's estimate when it was made
  Eigen::Isometry3d T_previous_this = Eigen::Isometry3d::Identity();   // relative to the previous keyframe
  geometry::Matrix6d degenerate_cov = geometry::Matrix6d::Zero();      // as LoopClosure::addKeyframe takes it
  // Older keyframes this one's arrival retired (LocalMap::supersededBy, decided with the LIS's poses now): a copy of
  // the map retires them too, after this keyframe's loop search (LoopClosure::retire as well). Ascending;
  // retired_by[k] is the newer keyframe that stands for retired[k].
  std::vector<std::size_t> retired;
  std::vector<std::size_t> retired_by;
};

// Keyframe poses corrected by an accepted loop (LIO-SAM's correctPoses input): T_world_lidar of keyframes
// 0 .. poses.size() - 1, the last being the loop's query.
struct LoopCorrection {
  std::vector<Eigen::Isometry3d> poses;
  LoopEvent event;
};

class LidarOdometry {
 public:
  // Throws std::invalid_argument when the config is invalid (names the bad value).
  LidarOdometry(const OdometryConfig& config, const Calibration& calibration);
  ~LidarOdometry();
  LidarOdometry(const LidarOdometry&) = delete;
  LidarOdometry& operator=(const LidarOdometry&) = delete;

  // Feeds one measurement (time order). With an IMU a sweep waits until the IMU covers its end (readers emit a
  // sweep at its start time), so the outcomes returned are those of the sweeps completed by this measurement.
  std::vector<ScanOutcome> process(const Measurement& measurement);
  // Processes the sweeps still waiting for IMU data (end of the stream).
  std::vector<ScanOutcome> finish();

  // T_world_lidar at every processed sweep's start; after a loop closure every pose is re-expressed relative to
  // its keyframe's corrected pose (the pose relative to the keyframe the sweep followed is kept). Built on each
  // call from the keyframes' poses (O(sweeps)): call it once, not per sweep.
  Trajectory trajectory() const;
  Trajectory keyframeTrajectory() const;    // T_world_lidar of the keyframes
  // IMU-rate odometry (LIO-SAM's imuPreintegration output), T_world_imu at every accepted IMU sample after the
  // initialisation: the newest fused state propagated by the IMU as each sample arrives, i.e. what a live system
  // would publish at that moment. Causal: loop corrections move it from the next sample on, never backwards. None
  // without the IMU. Every pose goes to the listener (drover run streams them to trajectory_imu_rate.tum); the
  // last kImuRateKept of them are kept (the VIS's pose lookups).
  static constexpr Time kImuRateKept = 10'000'000'000;  // [ns]
  using ImuRateListener = std::function<void(const StampedPose& T_world_imu)>;
  void setImuRateListener(ImuRateListener listener);
  const std::deque<StampedPose>& recentImuRate() const;
  std::size_t keyframeBytes() const;  // [bytes] the keyframe map's feature clouds
  const lidar::LocalMap& keyframeMap() const;  // every keyframe (retired ones marked), poses as corrected
  // The keyframes' full clouds in the world frame, voxel-downsampled with leaf [m].
  lidar::PointCloud mapCloud(float leaf) const;
  const OdometryStats& stats() const;
  const OdometryConfig& config() const;
  const LoopClosure& loopClosure() const;  // loop events and statistics

  // Where the VIS plugs in: called for every processed sweep with its deskewed, downsampled points in the lidar
  // frame at the sweep's start and the estimated T_world_lidar there (the VIS's lidar depth comes from these).
  using SweepListener = std::function<void(Time t, const Eigen::Isometry3d& T_world_lidar,
                                           const std::vector<Eigen::Vector3f>& points_lidar)>;
  void setSweepListener(SweepListener listener);
  // The VIS's newest state after each of its camera frames, in time order (LVI-SAM's VIS -> LIS link): while the
  // VIS is healthy, its motion between sweeps is the matcher's initial guess and a relative-pose factor in the IMU
  // smoother (config().vis_fusion; pipeline/visual_motion.hpp). Ignored without the IMU.
  void addVisualState(const VisualState& state);

  // Live use (pipeline::System): every new keyframe goes to `listener`; with `external_loops` the in-line loop
  // closure no longer runs (loopClosure() stays empty) and the loops come back through applyLoopCorrection. Set
  // before the first measurement.
  using KeyframeListener = std::function<void(const KeyframeRecord& keyframe)>;
  void setKeyframeListener(KeyframeListener listener, bool external_loops);
  // Moves the keyframes 0..n-1 onto the correction's poses and the keyframes made since its query rigidly with the
  // query; the trajectory, the current local map and the IMU smoother follow (as after an in-line loop). Throws
  // std::invalid_argument when the correction names more keyframes than the map has.
  // Returns T_new_old of the newest keyframe (what the IMU smoother and the VIS's lidar sweeps follow).
  Eigen::Isometry3d applyLoopCorrection(const LoopCorrection& correction);
  // Live use (pipeline::System, while it waits for the next sweep): after a keyframe or a loop correction changed
  // the map, builds the local map around the newest keyframe, which the next sweep then most likely reuses, so the
  // rebuild (~20 ms on the farm course) is not in that sweep's latency. Changes no result: a sweep whose selection
  // of keyframes differs rebuilds anyway. Returns whether it built.
  bool prepareMap();
  // The IMU smoother's newest fused state (IMU mode, once initialised): where the IMU-rate odometry starts from.
  std::optional<imu::FusedState> fusedImuState() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::pipeline
