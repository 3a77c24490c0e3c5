#include "pipeline/visual_motion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/so3.hpp"

namespace drover::pipeline {

std::string VisualMotionConfig::validate() const {
  for (const auto& [name, v] : {std::pair<const char*, double>{"sigma_position", sigma_position},
                                {"sigma_rotation", sigma_rotation},
                                {"max_age", max_age},
                                {"max_keyframe_gap", max_keyframe_gap},
                                {"max_velocity_difference", max_velocity_difference},
                                {"max_position_difference", max_position_difference},
                                {"max_acceleration_difference", max_acceleration_difference},
                                {"window_floor_position", window_floor_position},
                                {"window_floor_rotation", window_floor_rotation}})
    if (!std::isfinite(v) || v <= 0) return fmt::format("{} must be finite and > 0, got {}", name, v);
  for (const auto& [name, v] : {std::pair<const char*, double>{"sigma_position_ratio", sigma_position_ratio},
                                {"sigma_rotation_ratio", sigma_rotation_ratio},
                                {"max_velocity_difference_ratio", max_velocity_difference_ratio},
                                {"max_velocity_difference_growth", max_velocity_difference_growth},
                                {"warmup", warmup},
                                {"reset_after", reset_after},
                                {"standing_speed", standing_speed},
                                {"keyframe_gap_min_distance", keyframe_gap_min_distance},
                                {"keyframe_gap_velocity_tolerance", keyframe_gap_velocity_tolerance}})
    if (!std::isfinite(v) || v < 0) return fmt::format("{} must be finite and >= 0, got {}", name, v);
  if (min_features < 1 || full_features < min_features)
    return fmt::format("need 0 < min_features <= full_features, got {} and {}", min_features, full_features);
  return {};
}

std::optional<VisualState> VisualStateStream::onFrame(const vio::FrameResult& r) {
  if (r.just_initialized || r.rescaled) {  // the VIS's world starts again: no motion measured across it
    ++init_count_;
    init_time_ = keyframe_time_ = r.t;
    keyframe_interval_ = 0;
  }
  if (!r.initialized) return std::nullopt;
  if (r.keyframe && !r.keyframe_by_time) {  // the stall gate asks when the VIS last saw parallax
    keyframe_interval_ = r.t - keyframe_time_;
    keyframe_time_ = r.t;
  }
  return VisualState{r.t,         r.T_world_imu, r.v_world,      r.bias,           r.features,
                     init_count_, init_time_,    keyframe_time_, keyframe_interval_,
                     r.just_initialized ? std::nullopt : r.relative_covariance};
}

VisualMotion::VisualMotion(const VisualMotionConfig& config, const imu::PreintegrationConfig& imu)
    : config_(config), imu_(imu) {
  if (const std::string err = config.validate(); !err.empty())
    throw std::invalid_argument("VisualMotionConfig: " + err);
}

void VisualMotion::add(const VisualState& state) {
  if (!states_.empty() && state.t <= states_.back().t) return;
  if (!state.T_world_imu.matrix().allFinite() || !state.v_world.allFinite()) return;
  states_.push_back(state);
  while (states_.front().t < state.t - kKept) states_.pop_front();
}

std::optional<imu::NavState> VisualMotion::stateAt(Time t, const imu::ImuPropagator& imu, const VisualState** used,
                                                  std::string* why) const {
  const auto it = std::upper_bound(states_.begin(), states_.end(), t,
                                   [](Time x, const VisualState& s) { return x < s.t; });
  if (it == states_.begin()) {
    *why = "no VIS state before the sweep";
    return std::nullopt;
  }
  const VisualState& s = *std::prev(it);
  *used = &s;
  if (t - s.t > fromSeconds(config_.max_age)) {
    *why = fmt::format("the VIS's newest state is {:.2f} s old", toSeconds(t - s.t));
    return std::nullopt;
  }
  if (s.t - s.initialized_at < fromSeconds(config_.warmup)) {
    *why = "the VIS initialised less than warmup ago";
    return std::nullopt;
  }
  if (s.features < config_.min_features) {
    *why = fmt::format("the VIS solved with {} features (< {})", s.features, config_.min_features);
    return std::nullopt;
  }
  if (s.t == t) return imu::NavState{s.t, s.T_world_imu, s.v_world};
  const std::vector<ImuSample> samples = imu.samplesCovering(s.t, t);
  if (samples.empty() || samples.back().t < t) {
    *why = "no IMU samples from the VIS state to the sweep";
    return std::nullopt;
  }
  imu::Preintegrator pim(s.bias, imu_);
  pim.integrateRange(samples, s.t, t);
  return pim.predict(imu::NavState{s.t, s.T_world_imu, s.v_world}, s.bias);
}

// The frames' relative covariances are each in their previous frame's IMU frame; summed as independent steps after
// rotating each into a's frame (the steps' own rotations are small between two sweeps).
std::optional<Eigen::Matrix<double, 6, 6>> VisualMotion::windowCovariance(const VisualState* a,
                                                                          const VisualState* b) const {
  Eigen::Matrix<double, 6, 6> sum = Eigen::Matrix<double, 6, 6>::Zero();
  sum.diagonal() << Eigen::Vector3d::Constant(config_.window_floor_position * config_.window_floor_position),
      Eigen::Vector3d::Constant(config_.window_floor_rotation * config_.window_floor_rotation);
  const Eigen::Matrix3d R_world_a = a->T_world_imu.linear();
  auto it = std::upper_bound(states_.begin(), states_.end(), a->t,
                             [](Time x, const VisualState& s) { return x < s.t; });
  const VisualState* previous = a;
  for (; it != states_.end() && it->t <= b->t; ++it) {
    if (!it->relative_covariance) return std::nullopt;
    Eigen::Matrix<double, 6, 6> G = Eigen::Matrix<double, 6, 6>::Zero();
    const Eigen::Matrix3d R_a_prev = R_world_a.transpose() * previous->T_world_imu.linear();
    G.topLeftCorner<3, 3>() = G.bottomRightCorner<3, 3>() = R_a_prev;
    sum += G * *it->relative_covariance * G.transpose();
    previous = &*it;
  }
  return sum;
}

std::optional<VisualIncrement> VisualMotion::increment(Time a, Time b, const imu::ImuPropagator& imu,
                                                       std::string* why) const {
  std::string reason;
  std::string* w = why != nullptr ? why : &reason;
  if (!(a < b)) {
    *w = "the sweep stamps are not increasing";
    return std::nullopt;
  }
  const VisualState* sa = nullptr;
  const VisualState* sb = nullptr;
  const std::optional<imu::NavState> xa = stateAt(a, imu, &sa, w);
  if (!xa) return std::nullopt;
  const std::optional<imu::NavState> xb = stateAt(b, imu, &sb, w);
  if (!xb) return std::nullopt;
  if (sa->reset_id != sb->reset_id) {
    *w = "the VIS reset between the sweeps";
    return std::nullopt;
  }
  VisualIncrement inc;
  inc.T_a_b = xa->T_world_imu.inverse() * xb->T_world_imu;
  inc.v_b = xb->T_world_imu.linear().transpose() * xb->v_world;
  inc.last_keyframe_at = sb->last_keyframe_at;
  inc.keyframe_interval = sb->keyframe_interval;
  inc.gravity_b = xb->T_world_imu.linear().transpose() * Eigen::Vector3d(0, 0, -imu_.gravity);
  inc.acc_bias_b = sb->bias.acc;
  inc.sqrt_information.setZero();
  if (config_.window_covariance) {
    if (const std::optional<Eigen::Matrix<double, 6, 6>> cov = windowCovariance(sa, sb)) {
      const Eigen::Matrix<double, 6, 6> information = cov->inverse();
      inc.sqrt_information = Eigen::LLT<Eigen::Matrix<double, 6, 6>>(0.5 * (information + information.transpose()))
                                 .matrixU();
      if (inc.sqrt_information.allFinite()) return inc;
    }
  }
  // Fewer features than a full frame: the sigmas grow as 1/sqrt(n), as a mean over n independent features would.
  const int n = std::min(sa->features, sb->features);
  const double scale = std::sqrt(static_cast<double>(config_.full_features) / std::min(n, config_.full_features));
  const double moved = inc.T_a_b.translation().norm();
  const double turned = geometry::logSO3(inc.T_a_b.linear()).norm();
  const double sp = scale * (config_.sigma_position + config_.sigma_position_ratio * moved);
  const double sr = scale * (config_.sigma_rotation + config_.sigma_rotation_ratio * turned);
  inc.sqrt_information.diagonal() << Eigen::Vector3d::Constant(1 / sp), Eigen::Vector3d::Constant(1 / sr);
  return inc;
}

}  // namespace drover::pipeline

namespace drover::pipeline {

std::string disagreementWithImu(const VisualIncrement& inc, const imu::NavState& a, const imu::NavState& b,
                                const VisualMotionConfig& config, const KeyframeTravel& travel, double unmeasured_s) {
  const Eigen::Vector3d v_b_imu = b.T_world_imu.linear().transpose() * b.v_world;
  // A gap is a stall only when the robot moved over it: since the newest keyframe, or between it and the one before
  // (a lone keyframe after a stall).
  const double min_travel = config.keyframe_gap_min_distance;
  const double since = toSeconds(b.t - inc.last_keyframe_at), interval = toSeconds(inc.keyframe_interval);
  const double gap = std::max(since > config.max_keyframe_gap && travel.since_keyframe >= min_travel ? since : 0.0,
                              interval > config.max_keyframe_gap && travel.keyframe_interval >= min_travel ? interval
                                                                                                        : 0.0);
  const double dv = (inc.v_b - v_b_imu).norm();
  const double speed = v_b_imu.norm(), unmeasured = std::max(0.0, unmeasured_s);
  const bool holds_speed = config.keyframe_gap_velocity_tolerance > 0 &&
                           dv <= config.keyframe_gap_velocity_tolerance + config.max_velocity_difference_ratio * speed;
  if (gap > 0 && speed > config.standing_speed && !holds_speed)
    return fmt::format("the VIS made no keyframe for {:.1f} s while moving at {:.2f} m/s (its velocity {:.2f} m/s off)",
                       gap, speed, dv);
  const double dv_max = config.max_velocity_difference + config.max_velocity_difference_ratio * speed +
                        config.max_velocity_difference_growth * unmeasured;
  if (dv > dv_max)
    return fmt::format("the VIS's velocity differs from the IMU's prediction by {:.2f} m/s (at {:.2f} m/s, {:.1f} s "
                       "since the LIS's velocity was measured: at most {:.2f})",
                       dv, speed, unmeasured, dv_max);
  const Eigen::Vector3d dp_imu = a.T_world_imu.linear().transpose() * (b.T_world_imu.translation() -
                                                                       a.T_world_imu.translation());
  const double dp = (inc.T_a_b.translation() - dp_imu).norm();
  if (dp > config.max_position_difference)
    return fmt::format("the VIS's motion differs from the IMU's prediction by {:.2f} m", dp);
  return {};
}

// The accelerometer reads f = R^T (a - g) + b_a: the body-frame acceleration is f - b_a + R^T g by either estimate.
std::string accelerationDisagreement(const VisualIncrement& inc, const imu::NavState& b, double gravity,
                                     const Eigen::Vector3d& lis_acc_bias, const VisualMotionConfig& config) {
  const Eigen::Vector3d gravity_lis = b.T_world_imu.linear().transpose() * Eigen::Vector3d(0, 0, -gravity);
  const double da = ((inc.gravity_b - gravity_lis) - (inc.acc_bias_b - lis_acc_bias)).norm();
  if (da <= config.max_acceleration_difference) return {};
  return fmt::format("the VIS's attitude and accelerometer bias make an acceleration {:.3f} m/s^2 off the LIS's of the "
                     "same IMU reading", da);
}

}  // namespace drover::pipeline

namespace drover::pipeline {

std::string VisualWatch::onSweep(Time t, bool used, const std::string& refused) {
  if (reset_after_ <= 0 || used || refused.empty()) {
    since_.reset();
    return {};
  }
  if (!since_) since_ = t;
  if (t - *since_ < reset_after_) return {};
  const double lasted = toSeconds(t - *since_);
  since_.reset();
  return fmt::format("the LIS refused the VIS for {:.1f} s ({})", lasted, refused);
}

}  // namespace drover::pipeline
