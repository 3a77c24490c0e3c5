#pragma once
// The sliding-window visual-inertial estimator (VINS-Mono, Qin et al. T-RO 2018, Sec. VI; LVI-SAM's lidar depth).
// States per window frame: p_world_imu, q_world_imu, v_world, biases [b_g; b_a]; shared: T_imu_cam (optionally
// refined) and the camera-IMU time offset td (optionally estimated; t_imu = t_camera + calibration offset + td);
// per feature: its inverse depth in the anchor camera. Per frame the cost is
//   marginal prior + sum IMU preintegration + bias random walk + sum rho(reprojection) [+ lidar inverse depth]
// solved by Ceres (DENSE_SCHUR, dogleg, a bounded number of iterations), after which outliers are dropped, the
// failure checks run, and one frame leaves the window by marginalisation: the oldest when the second-newest frame
// is a keyframe (enough parallax or few tracked features), else the second-newest (its IMU folded into the next).
// Before initialisation the window fills and slides without marginalisation; initialisation is from an external
// seed (the LIS: poses, velocities and biases at the frames' stamps) or visual-inertial alignment (Sec. V). Without a
// LIS, a window that loses its tracks coasts on the IMU for a while instead of being cleared.
// Deterministic: no wall-clock limit unless config.max_solver_ms applies (live use), single-threaded solver.
#include <Eigen/Geometry>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"
#include "vio/feature_manager.hpp"
#include "vio/scale_check.hpp"
#include "vio/vio_config.hpp"

namespace ceres {
class CostFunction;
}

namespace drover::backend {
class MarginalPriorFactor;
class SchurMarginalizer;
}

namespace drover::vio {

// An externally known state at a camera stamp (the LIS's IMU-rate state). A Seeder is given while the LIS runs
// (even before it can answer): initialisation then waits for it instead of aligning visually.
struct SeedState {
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();  // [m/s]
  imu::ImuBias bias;
};
using Seeder = std::function<std::optional<SeedState>(Time)>;

// What one frame did.
struct FrameResult {
  Time t = 0;                       // [ns] the frame's stamp in IMU time (with the estimated td)
  bool initialized = false;         // the window is initialised and the state below is an estimate
  bool just_initialized = false;
  bool coasting = false;            // too few features tracked and no LIS: the window goes on on the IMU
  bool reset = false;               // a failure cleared the window at this frame
  bool rescaled = false;            // the scale check rescaled and tilted the window before this frame's output:
                                    // its pose is not continuous with the previous frame's (like an initialisation)
  std::string event;                // why initialisation waits, how it succeeded, or why the window was reset
  bool keyframe = false;            // the second-newest frame was kept (the oldest was marginalised)
  bool keyframe_by_time = false;    // ... by vio.max_keyframe_interval_s alone (too little parallax for one)
  int tracked = 0;                  // features of this frame already in the window
  int features = 0;                 // features used in the solve
  int with_lidar_depth = 0;         // of those, anchored on a lidar depth
  int on_ground = 0;                // of those, held to the ground below the robot (vio ground_height_m)
  int outliers = 0;                 // observations dropped after the solve
  int iterations = 0;
  double ms_solve = 0, ms_marginalize = 0, ms_covariance = 0;  // [ms]
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  imu::ImuBias bias;
  double td = 0;                    // [s] estimated time offset on top of the calibration's
  // The covariance of this frame's pose relative to the previous frame's, [dp in the previous frame's IMU frame (m);
  // dtheta (rad)], from the window's information with everything else marginalised (vio.relative_covariance).
  std::optional<Eigen::Matrix<double, 6, 6>> relative_covariance;
};

class SlidingWindowEstimator {
 public:
  // Throws std::invalid_argument when a config is invalid or focal_px <= 0.
  SlidingWindowEstimator(const VioConfig& config, const imu::PreintegrationConfig& imu_config,
                         const Eigen::Isometry3d& T_imu_cam, double focal_px);
  ~SlidingWindowEstimator();
  SlidingWindowEstimator(const SlidingWindowEstimator&) = delete;
  SlidingWindowEstimator& operator=(const SlidingWindowEstimator&) = delete;

  // IMU samples in time order (the caller checks them); a frame at t needs the samples up to t.
  void addImu(const ImuSample& sample);
  // One camera frame: t_camera in IMU time without td (stamp + calibration offset). seed may be empty (no LIS).
  FrameResult addFrame(Time t_camera, const std::vector<FrameFeature>& features, const Seeder& seed);

  bool initialized() const { return initialized_; }
  double timeOffset() const { return td_[0]; }
  Eigen::Isometry3d T_imu_cam() const;
  int windowSize() const { return static_cast<int>(frames_.size()); }
  // Share of the solved features observed in >= 3 window keyframes (the track-length question), last frame.
  double featuresInThreeOrMore() const { return share_three_; }
  // Scale checks run since construction (vio/scale_check.hpp; only after visual-inertial initialisations).
  int scaleChecks() const { return scale_checks_; }
  void reset();  // clears everything (a failure, or the caller's reset)
  // Live use: the solver stops at config.max_solver_ms (results then depend on timing). Replay: iterations only.
  void setRealtime(bool realtime) { deterministic_ = !realtime; }

 private:
  struct Frame;
  struct Residuals;
  Time imuTime(Time t_camera) const;
  std::vector<ImuSample> takeImu(Time t0, Time t1);
  void integrate(Frame& frame, const Frame& previous) const;
  void predict(Frame& frame, const Frame& previous) const;
  bool tryInitialize(const Seeder& seed, FrameResult& result);
  bool initializeFromSeed(const Seeder& seed, std::string& why);  // why: the refusal, or how the seed agreed
  bool initializeVisually(std::string& why);
  std::vector<Eigen::Isometry3d> cameraPoses() const;
  void optimize(FrameResult& result);
  void buildResiduals(Residuals& r, bool for_marginalization_of_oldest) const;
  void addGroundFactor(Residuals& r, Feature& f, const Eigen::Isometry3d& T_ic) const;  // alone_, a ground height set
  void removeOutliers(FrameResult& result);
  // Why the window failed (empty: it did not). Too few tracked features are one reason unless result.coasting.
  std::string failure(const FrameResult& result) const;
  // Without a LIS, too few tracked features for up to vio.coast_max_s do not clear the window: sets result.coasting.
  void checkCoasting(FrameResult& result, bool has_seed);
  // vio.max_keyframe_interval_s: the second-newest frame came that long after the keyframe before it.
  bool keyframeIsDue() const;
  void slide(bool keyframe, FrameResult& result);
  void declareWindowBlocks(backend::SchurMarginalizer& m);
  // declareWindowBlocks, then the window's residuals (buildResiduals) and their feature blocks declared in the
  // features' order: what the marginalisation and the relative covariance start from.
  Residuals declareWindow(backend::SchurMarginalizer& m, bool for_marginalization_of_oldest);
  // A held (depth_mode fixed) lidar depth as a tight inverse-depth factor, so that a Schur complement conditions on
  // it rather than forgetting it (window_marginalize.cpp; the marginalisation and the relative covariance).
  struct HeldDepth {
    std::unique_ptr<ceres::CostFunction> factor;
    double* inverse_depth = nullptr;
  };
  std::vector<HeldDepth> heldDepths(const Residuals& r);
  void marginalizeOldest();
  void marginalizeSecondNewest();
  void fixGauge(const Eigen::Isometry3d& T_world_imu0_before);
  void fillResult(FrameResult& result) const;
  std::optional<Eigen::Matrix<double, 6, 6>> newestRelativeCovariance();  // window_covariance.cpp

  VioConfig config_;
  imu::PreintegrationConfig imu_config_;
  double focal_px_;
  double p_ic_[3], q_ic_[4];  // T_imu_cam parameter blocks (q in Eigen x, y, z, w order)
  double td_[1] = {0};        // [s]
  std::deque<std::unique_ptr<Frame>> frames_;  // stable addresses: the marginal prior points into them
  FeatureManager features_;
  std::deque<ImuSample> imu_;
  Eigen::Vector3d raw_newest_omega_ = Eigen::Vector3d::Zero(), raw_newest_acc_ = Eigen::Vector3d::Zero();
  std::unique_ptr<backend::MarginalPriorFactor> prior_;
  bool initialized_ = false;
  std::optional<FrameResult> last_output_;
  double share_three_ = 0;
  bool deterministic_ = true;
  bool solver_failed_ = false;
  bool waiting_for_older_ = false;  // initialisation waits for a seed the oldest frame predates
  // The initialisation's knowledge of the oldest frame (pose, velocity, biases) as a prior with these sigmas
  // (tangent order p, theta, v, b_g, b_a); it holds the gauge and the tilt / accelerometer-bias ambiguity of a
  // straight drive until the first marginalisation folds it into the marginal prior.
  struct InitPrior {
    bool active = false;
    Eigen::Matrix<double, 15, 1> sigma = Eigen::Matrix<double, 15, 1>::Ones();
    double p[3], q[4], v[3], bias[6];  // the oldest frame's state at initialisation
  };
  InitPrior init_prior_;
  // The LIS's biases at the newest frame (vio.lis_bias_prior_sigma_*): a prior in its solves only.
  std::optional<imu::ImuBias> lis_bias_;
  Time last_ground_check_ = 0;
  std::optional<double> pending_ground_scale_;  // log of the scale the previous ground check found, to be confirmed
  // No LIS seeds the window at this frame: only then do the ground factors (ground_height_m) and the turn-on bias
  // prior (acc_bias_prior_sigma) act; beside the LIS its lidar gives the scale and its biases seed the window.
  bool alone_ = false;
  // The scale check after a visual initialisation (window_scale_check.cpp): the keyframes that left the window,
  // each with the IMU from the one before, and the IMU from the newest of them to the window's oldest frame.
  std::deque<ScaleCheckFrame> history_;
  std::vector<ImuSample> history_next_imu_;
  bool aligned_visually_ = false;
  Time last_scale_check_ = 0;
  int scale_checks_ = 0;
  std::string scale_failure_;                  // a check found the scale off beyond repair: failure() says it
  void recordOldest();                         // before the oldest frame leaves the window
  void checkScaleOverHistory(FrameResult& result);
  void checkGroundScale(FrameResult& result);  // window_ground_check.cpp
  void applyScale(const ScaleCheck& check, double rel_sigma);  // rel_sigma: the scale's, bias error included
  void setInitPrior(double sigma_rotation, double sigma_velocity, double sigma_gyro_bias, double sigma_acc_bias);
  // Coasting (no LIS; vio.coast_max_s): since when the newest frames have had too few tracked features.
  std::optional<Time> coasting_since_;
};

}  // namespace drover::vio
