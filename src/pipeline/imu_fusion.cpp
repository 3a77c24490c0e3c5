#include "pipeline/imu_fusion.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "pipeline/motion_models.hpp"

namespace drover::pipeline {
namespace {

void appendWarning(ScanOutcome& out, const std::string& w) { out.warning += (out.warning.empty() ? "" : "; ") + w; }

// How far the LIS moved over the VIS's keyframe gaps: the fused path up to the newest fused state (xa), then the
// prediction's straight line to the sweep (xb), the share of it after the keyframe.
KeyframeTravel travelOf(const PathOdometer& odometer, const VisualIncrement& inc, const imu::NavState& xa,
                        const imu::NavState& xb) {
  const double ahead = (xb.T_world_imu.translation() - xa.T_world_imu.translation()).norm();
  const Time kf = inc.last_keyframe_at;
  const double share = kf <= xa.t || xb.t <= xa.t ? 1.0
                                                  : std::max(0.0, toSeconds(xb.t - kf) / toSeconds(xb.t - xa.t));
  KeyframeTravel travel;
  travel.since_keyframe = odometer.between(kf, xa.t) + share * ahead;
  travel.keyframe_interval = odometer.between(kf - inc.keyframe_interval, kf);
  return travel;
}

// Velocity of the IMU from the last two lidar poses [m/s] (for a restart), zero with fewer.
Eigen::Vector3d velocityFrom(const Trajectory& trajectory, const Eigen::Isometry3d& T_lidar_imu) {
  if (trajectory.size() < 2) return Eigen::Vector3d::Zero();
  const StampedPose& a = trajectory[trajectory.size() - 2];
  const StampedPose& b = trajectory.back();
  const double dt = toSeconds(b.t - a.t);
  if (!(dt > 0)) return Eigen::Vector3d::Zero();
  return ((b.T_world_body * T_lidar_imu).translation() - (a.T_world_body * T_lidar_imu).translation()) / dt;
}

}  // namespace

ImuFusion::ImuFusion(const OdometryConfig& config, const Eigen::Isometry3d& T_imu_lidar)
    : config_(config),
      T_imu_lidar_(T_imu_lidar),
      T_lidar_imu_(T_imu_lidar.inverse()),
      propagator_(config.propagator),
      initializer_(config.initializer),
      smoother_(config.smoother),
      visual_(config.vis_fusion, config.preintegration),
      visual_watch_(config.vis_fusion.reset_after),
      hold_(config.static_hold) {}

imu::SampleStatus ImuFusion::addImu(const ImuSample& sample) { return propagator_.addSample(sample); }

bool ImuFusion::wantsImu() const { return config_.use_imu && !given_up_ && propagator_.stats().accepted > 0; }

Time ImuFusion::coverageNeeded(Time t0, Time t_end, bool first_sweep) const {
  if (!first_sweep || initialized_) return t_end;
  return std::max(t_end, t0 + fromSeconds(config_.initializer.window_s));
}

void ImuFusion::tryInitialize(Time t0, bool first_sweep) {
  if (initialized_ || given_up_ || !config_.use_imu) return;
  if (!first_sweep || propagator_.stats().accepted == 0) {
    // The world frame is fixed by the first sweep; an IMU that starts later cannot be aligned to it here.
    given_up_ = true;
    init_note_ = first_sweep ? "no IMU sample before the first sweep: lidar only"
                             : "IMU data started after the first sweep: lidar only";
    return;
  }
  const Time window_end = t0 + fromSeconds(config_.initializer.window_s);
  std::vector<ImuSample> window;
  for (const ImuSample& s : propagator_.samples())
    if (s.t <= window_end) window.push_back(s);
  const imu::StaticInitializer::Result r = initializer_.initialize(window);
  if (!r.ok) {
    given_up_ = true;
    init_note_ = "IMU initialisation failed (" + r.reason + "): lidar only";
    return;
  }
  T_world_imu0_ = Eigen::Isometry3d(r.q_world_imu.normalized());
  imu::NavState state;
  state.t = t0;
  state.T_world_imu = T_world_imu0_;
  restart(state, r.bias);
  // At rest by the IMU window: the velocity is known (zero), not merely unknown around zero.
  if (r.is_static && config_.static_start_sigma_velocity > 0)
    smoother_.setFirstVelocitySigma(config_.static_start_sigma_velocity);
  // The rest is what the initialiser judged: its window's mean specific force and rate (the gyro bias).
  if (r.is_static) hold_.begin(r.window_end, r.mean_specific_force, r.bias.gyro);
  initialized_ = true;
  sweeps_to_moving_restart_ = config_.moving_start_restart > 0 ? config_.moving_start_restart : kDone;
  static_start_ = r.is_static;
  start_bias_ = r.bias;
  t_start_ = t0;
  init_note_ = r.is_static
                   ? fmt::format("static start: gravity {:.3f} m/s^2, gyro bias ({:.4f}, {:.4f}, {:.4f}) rad/s{}",
                                 r.gravity_magnitude, r.bias.gyro.x(), r.bias.gyro.y(), r.bias.gyro.z(),
                                 r.used_orientation ? ", attitude from the 9-axis orientation" : "")
                   : "moving start (" + r.reason + "): attitude from the " +
                         (r.used_orientation ? "9-axis orientation" : "mean specific force") + ", velocity 0";
}

void ImuFusion::restart(const imu::NavState& state, const imu::ImuBias& bias,
                        const std::optional<Eigen::Matrix3d>& gyro_bias_covariance,
                        const std::optional<Eigen::Matrix<double, 6, 6>>& bias_covariance) {
  smoother_.reset();
  if (bias_covariance) {
    smoother_.initialize(state, bias, config_.preintegration, *bias_covariance);
  } else if (gyro_bias_covariance) {
    smoother_.initialize(state, bias, config_.preintegration, *gyro_bias_covariance);
  } else {
    smoother_.initialize(state, bias, config_.preintegration);
  }
  propagator_.reset(state, bias);
  odometer_.add(state.t, state.T_world_imu.translation());
  velocity_measured_at_ = state.t;
}

// The smoother restarts in the corrected world (LIO-SAM resets its IMU graph on the corrected odometry), but the
// gyro bias keeps the certainty the window had: it is a body-frame quantity the correction does not touch. A plain
// restart re-centres the loose first-state prior (0.01 rad/s) on the current estimate at every loop, and with a
// loop every few seconds on the farm's second lap the gyro bias walked off by 0.03 rad/s, the heading by 30 deg.
// Position, rotation and velocity restart loose. So does the accelerometer bias when the correction tilts the world
// (a 6-DoF pose graph: on kitti05-replay its corrections are almost all tilt, up to 1 deg): the bias must then be
// free to follow g * tilt. Moving the whole window with its information instead held the old gravity against the
// tilted map (kitti05-replay APE 0.42 -> 0.64 m). A 4-DoF graph (loop.four_dof_with_imu) turns the world about
// gravity only, which changes neither bias: the accelerometer bias keeps its certainty as well. Restarted loose at
// every loop, it wandered 0.1 m/s^2 on the farm's second lap, what the corridor then integrated (bench/RESULTS.md).
void ImuFusion::reanchor(const Eigen::Isometry3d& T_new_old) {
  if (!initialized_ || !smoother_.initialized()) return;
  imu::NavState state = smoother_.state();
  state.T_world_imu = T_new_old * state.T_world_imu;
  state.v_world = T_new_old.linear() * state.v_world;
  odometer_.moveWorld(T_new_old);  // a correction is no motion
  const double tilt = (T_new_old.linear() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ()).norm();  // [rad]
  const Time measured = velocity_measured_at_;  // the velocity is carried over, not measured
  if (tilt < 1e-9) {
    restart(state, smoother_.bias(), std::nullopt, smoother_.biasCovariance());
  } else {
    restart(state, smoother_.bias(), smoother_.gyroBiasCovariance());
  }
  velocity_measured_at_ = measured;
}

// The biases' covariance after `gap` seconds without the IMU in the smoother: the window's, grown by the random walk
// over the gap (Forster Eq. 48). The biases are body-frame quantities a gap does not move, so a restart across one
// keeps what the window knew of them instead of re-centring the loose first-state priors (0.01 rad/s, 0.1 m/s^2).
std::optional<Eigen::Matrix<double, 6, 6>> ImuFusion::biasCovarianceAfter(double gap) const {
  std::optional<Eigen::Matrix<double, 6, 6>> C = smoother_.biasCovariance();
  if (!C || !(gap > 0)) return C;
  const double g = config_.preintegration.gyro_bias_random_walk, a = config_.preintegration.acc_bias_random_walk;
  C->diagonal().head<3>().array() += g * g * gap;
  C->diagonal().tail<3>().array() += a * a * gap;
  return C;
}

bool ImuFusion::restartAfterMovingStart(ScanOutcome& out, const Eigen::Isometry3d& T_world_imu_measured,
                                        const Trajectory& trajectory) {
  // Counts down to the configured sweep, then below zero through the retries a sweep without a lidar velocity
  // (a failed or degenerate match) costs; a start still unjudged a second later is left as it is: by then the
  // lidar's velocity says nothing about the start.
  constexpr int kRetries = 10;  // [sweeps]
  if (sweeps_to_moving_restart_ == kDone || --sweeps_to_moving_restart_ > 0) return false;
  const double dt = trajectory.empty() ? 0.0 : toSeconds(out.t - trajectory.back().t);
  if (!out.match_usable || out.degenerate || !(dt > 0)) {
    if (sweeps_to_moving_restart_ < -kRetries) sweeps_to_moving_restart_ = kDone;
    return false;
  }
  sweeps_to_moving_restart_ = kDone;
  const Eigen::Isometry3d T_world_imu_previous = trajectory.back().T_world_body * T_lidar_imu_;
  const Eigen::Vector3d v_world = (T_world_imu_measured.translation() - T_world_imu_previous.translation()) / dt;
  if (static_start_ && v_world.norm() <= config_.moving_start_speed) return false;  // at rest indeed
  restart({out.t, T_world_imu_measured, v_world}, start_bias_);
  hold_ = StaticHold(config_.static_hold);  // not at rest after all
  init_note_ += fmt::format("; moving at {:.2f} m/s by the lidar: the smoother restarted {:.2f} s in with that velocity",
                            v_world.norm(), toSeconds(out.t - t_start_));
  return true;
}

std::optional<imu::FusedState> ImuFusion::fusedState() const {
  if (!initialized_ || !smoother_.initialized()) return std::nullopt;
  return imu::FusedState{smoother_.state(), smoother_.bias()};
}

std::optional<lidar::SweepMotion> ImuFusion::sweepMotion(Time t0, Time t_end) const {
  if (!initialized_) return std::nullopt;
  return imuMotion(propagator_, T_imu_lidar_, t0, t_end);
}

std::optional<Eigen::Isometry3d> ImuFusion::predictLidarPose(Time t) const {
  const std::optional<Eigen::Isometry3d> T_world_imu = propagatedImuPose(t);
  if (!T_world_imu) return std::nullopt;
  return *T_world_imu * T_imu_lidar_;
}

std::optional<Eigen::Isometry3d> ImuFusion::propagatedImuPose(Time t) const {
  if (!initialized_) return std::nullopt;
  const std::optional<imu::NavState> s = propagator_.stateAt(t);
  if (!s) return std::nullopt;
  return s->T_world_imu;
}

Eigen::Isometry3d ImuFusion::initialLidarPose() const {
  return initialized_ ? Eigen::Isometry3d(T_world_imu0_ * T_imu_lidar_) : Eigen::Isometry3d::Identity();
}

void ImuFusion::update(ScanOutcome& out, const Trajectory& trajectory) {
  if (!initialized_) return;
  const imu::NavState previous = smoother_.state();
  if (out.t <= previous.t) return;  // the first sweep: the smoother starts there
  const Eigen::Isometry3d T_world_imu_measured = out.T_world_lidar * T_lidar_imu_;
  if (restartAfterMovingStart(out, T_world_imu_measured, trajectory)) return;
  const std::vector<ImuSample> samples = propagator_.samplesCovering(previous.t, out.t);
  if (samples.empty()) {
    appendWarning(out, "IMU does not cover the sweep: smoother restarted at the lidar pose");
    out.reset = true;
    restart({out.t, T_world_imu_measured, velocityFrom(trajectory, T_lidar_imu_)}, smoother_.bias(), std::nullopt,
            biasCovarianceAfter(toSeconds(out.t - previous.t)));
    return;
  }
  std::optional<backend::RelativePoseMeasurement> visual;
  // The VIS is checked (and watched) whenever the LIS takes it, as a factor or only as the matcher's guess.
  if ((config_.vis_fusion.factor || config_.vis_fusion.initial_guess) && !visual_.empty()) {
    std::string why;
    bool disagreed = false;
    const std::optional<VisualIncrement> inc = checkedVisualIncrement(previous.t, out.t, &why, &disagreed);
    if (inc && config_.vis_fusion.factor && (out.degenerate || !config_.vis_fusion.factor_degenerate_only)) {
      visual = backend::RelativePoseMeasurement{inc->T_a_b, inc->sqrt_information};
      out.vis_factor = true;
    } else if (!inc) {
      out.vis_unused = why;
    }
    out.vis_reset = visual_watch_.onSweep(out.t, inc.has_value(), disagreed ? why : std::string());
  }
  if (holdAtRest(samples, previous.t, out.t)) {
    visual = backend::RelativePoseMeasurement{Eigen::Isometry3d::Identity(), zeroMotionSqrtInformation()};
    out.vis_factor = false;
  }
  const Eigen::Matrix<double, 6, 6> L = poseSqrtInformation(out, T_world_imu_measured, visual.has_value());
  backend::SmootherUpdate r;
  try {
    imu::Preintegrator pim(smoother_.bias(), config_.preintegration);
    pim.integrateRange(samples, previous.t, out.t);
    r = smoother_.update(pim, T_world_imu_measured, L, visual);
  } catch (const std::invalid_argument& e) {
    r.failure = true;
    r.reason = e.what();
  }
  if (!r.ok) {
    appendWarning(out, "smoother reset: " + r.reason);
    out.reset = true;
    const imu::ImuBias bias = r.bias.gyro.allFinite() && r.bias.acc.allFinite() ? r.bias : imu::ImuBias{};
    restart({out.t, T_world_imu_measured, velocityFrom(trajectory, T_lidar_imu_)}, bias);
    return;
  }
  propagator_.reset(r.state, r.bias);
  odometer_.add(r.state.t, r.state.T_world_imu.translation());
  if ((out.match_usable && !out.degenerate) || visual) velocity_measured_at_ = r.state.t;
  out.has_imu_state = true;
  out.v_world = r.state.v_world;
  out.gyro_bias = r.bias.gyro;
  out.acc_bias = r.bias.acc;
  const Eigen::Isometry3d T_world_lidar_fused = r.state.T_world_imu * T_imu_lidar_;
  // A degenerate match whose guess was the VIS's motion, when no VO factor told the smoother that motion, holds the
  // VIS along its degenerate directions (Zhang's remapping keeps them at the guess); the smoother saw the VIS only
  // through the match's loosened directions and drifts there: the match is the pose (as LIO-SAM's). Without this a
  // guess-only Drover drifted 38.9 % in the corridor, and the VIS, taking its depths from the drifting LIS, with it.
  const bool guess_holds_degenerate = out.vis_guess && !out.vis_factor;
  const bool pose_from_match = config_.degenerate_pose_from_match || guess_holds_degenerate;
  if (!out.match_usable || (out.degenerate && !pose_from_match)) {
    // The lidar left some directions (or all) to the IMU: the fused state is the pose.
    out.T_world_lidar = T_world_lidar_fused;
  } else if (config_.gravity_roll_pitch) {
    out.T_world_lidar.linear() = geometry::withRollPitchOf(out.T_world_lidar.linear(), T_world_lidar_fused.linear());
  }
}

// Whether the sweep (a, b] is still at rest since the static start; the report's IMU note says when the hold ended.
bool ImuFusion::holdAtRest(const std::vector<ImuSample>& samples, Time a, Time b) {
  if (!hold_.holding()) return false;
  if (hold_.stillAtRest(samples, a, b)) return true;
  init_note_ += fmt::format("; held at rest until {:.2f} s ({})", toSeconds(hold_.endedAt() - t_start_),
                            hold_.endReason());
  return false;
}

// Zero motion between two sweeps at rest, [dp (m); dtheta (rad)] each with the hold's sigma.
Eigen::Matrix<double, 6, 6> ImuFusion::zeroMotionSqrtInformation() const {
  return Eigen::Matrix<double, 6, 6>::Identity() / config_.static_hold.sigma;
}

std::optional<Eigen::Isometry3d> ImuFusion::visualLidarGuess(Time t, const StampedPose& previous,
                                                              std::string* why) const {
  if (!config_.vis_fusion.initial_guess || visual_.empty() || !initialized_) return std::nullopt;
  const std::optional<VisualIncrement> inc = checkedVisualIncrement(previous.t, t, why);
  if (!inc) return std::nullopt;
  return previous.T_world_body * T_lidar_imu_ * inc->T_a_b * T_imu_lidar_;
}

// The VIS's motion between a and b while it agrees with the IMU's prediction from the newest fused state (the
// propagation starts there; a is that state's stamp).
std::optional<VisualIncrement> ImuFusion::checkedVisualIncrement(Time a, Time b, std::string* why,
                                                                 bool* disagreed) const {
  std::optional<VisualIncrement> inc = visual_.increment(a, b, propagator_, why);
  if (!inc) return std::nullopt;
  const std::optional<imu::NavState> xa = propagator_.stateAt(a), xb = propagator_.stateAt(b);
  if (!xa || !xb) return inc;  // no prediction to hold it against (the smoother restarts)
  std::string d = disagreementWithImu(*inc, *xa, *xb, config_.vis_fusion, travelOf(odometer_, *inc, *xa, *xb),
                                      toSeconds(b - velocity_measured_at_));
  if (d.empty())
    d = accelerationDisagreement(*inc, *xb, config_.preintegration.gravity, propagator_.bias().acc, config_.vis_fusion);
  if (!d.empty()) {
    if (why != nullptr) *why = std::move(d);
    if (disagreed != nullptr) *disagreed = true;
    return std::nullopt;
  }
  return inc;
}

// Sigma of the lidar pose: lidar_sigma_position/rotation (lidar_sigma_rotation_unaided on a degenerate sweep without
// a relative factor, when set), plus degenerate_sigma along each degenerate direction of the match (so the IMU
// carries those, e.g. along a featureless corridor), or degenerate_sigma on every axis when the match failed. The
// covariance is built in the lidar's right-perturbation tangent [rho; phi] and mapped to the smoother's error
// [dp_world; dtheta_imu]: xi_imu = Ad(T_imu_lidar) xi_lidar, dp_world = R_world_imu rho_imu.
Eigen::Matrix<double, 6, 6> ImuFusion::poseSqrtInformation(const ScanOutcome& out, const Eigen::Isometry3d& T_world_imu,
                                                           bool aided) const {
  using Matrix6d = Eigen::Matrix<double, 6, 6>;
  Matrix6d cov_lidar = Matrix6d::Zero();
  if (!out.match_usable) {
    cov_lidar.diagonal().setConstant(config_.degenerate_sigma * config_.degenerate_sigma);
  } else {
    const double sr = out.degenerate && !aided && config_.lidar_sigma_rotation_unaided > 0
                          ? config_.lidar_sigma_rotation_unaided
                          : config_.lidar_sigma_rotation;
    cov_lidar.diagonal() << Eigen::Vector3d::Constant(config_.lidar_sigma_position * config_.lidar_sigma_position),
        Eigen::Vector3d::Constant(sr * sr);
    for (const geometry::Vector6d& d : out.degenerate_directions)
      cov_lidar += config_.degenerate_sigma * config_.degenerate_sigma * d.normalized() * d.normalized().transpose();
  }
  Matrix6d G = geometry::adjointSE3(T_imu_lidar_);
  G.topRows<3>() = T_world_imu.linear() * G.topRows<3>();
  const Matrix6d cov = G * cov_lidar * G.transpose();
  const Matrix6d information = cov.inverse();
  return Eigen::LLT<Matrix6d>(0.5 * (information + information.transpose())).matrixU();
}

}  // namespace drover::pipeline
