#include "pipeline/static_hold.hpp"

#include <cmath>

#include <fmt/format.h>

namespace drover::pipeline {

std::string StaticHoldConfig::validate() const {
  if (!std::isfinite(sigma) || sigma < 0) return "sigma must be finite and >= 0";
  if (!std::isfinite(max_velocity) || max_velocity <= 0) return "max_velocity must be finite and > 0";
  if (!std::isfinite(max_rotation) || max_rotation <= 0) return "max_rotation must be finite and > 0";
  return {};
}

void StaticHold::begin(Time t, const Eigen::Vector3d& rest_specific_force, const Eigen::Vector3d& rest_rate) {
  holding_ = config_.sigma > 0;
  last_ = t;
  rest_f_ = rest_specific_force;
  rest_w_ = rest_rate;
  dv_.setZero();
  dtheta_.setZero();
  end_reason_.clear();
  ended_at_ = 0;
}

void StaticHold::end(Time t, std::string reason) {
  holding_ = false;
  ended_at_ = t;
  end_reason_ = std::move(reason);
}

bool StaticHold::stillAtRest(const std::vector<ImuSample>& samples, Time a, Time b) {
  if (!holding_) return false;
  for (const ImuSample& s : samples) {
    if (s.t <= a || s.t > b || s.t <= last_) continue;
    // Each sample holds over the interval up to it (the propagator's zero-order hold).
    const double dt = toSeconds(s.t - last_);
    last_ = s.t;
    dv_ += (s.acc_imu - rest_f_) * dt;
    dtheta_ += (s.omega_imu - rest_w_) * dt;
    if (dv_.norm() > config_.max_velocity) {
      end(s.t, fmt::format("the IMU measured a velocity change of {:.3f} m/s", dv_.norm()));
      return false;
    }
    if (dtheta_.norm() > config_.max_rotation) {
      end(s.t, fmt::format("the IMU measured a rotation of {:.4f} rad", dtheta_.norm()));
      return false;
    }
  }
  return true;
}

}  // namespace drover::pipeline
