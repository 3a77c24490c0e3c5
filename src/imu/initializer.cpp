#include "imu/initializer.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace drover::imu {

namespace {

struct WindowStats {
  Eigen::Vector3d mean_gyro = Eigen::Vector3d::Zero(), mean_acc = Eigen::Vector3d::Zero();
  double gyro_std = 0, acc_std = 0;  // root of the summed per-axis variances
  std::size_t count = 0;
  Time first = 0, last = 0;
  bool all_oriented = true;
  Eigen::Vector4d q_sum = Eigen::Vector4d::Zero();  // sign-aligned quaternion coefficients (chordal mean)
  Eigen::Vector4d q_first = Eigen::Vector4d::Zero();  // the window's first sample's orientation
};

bool finiteSample(const ImuSample& s) { return s.omega_imu.allFinite() && s.acc_imu.allFinite(); }

WindowStats windowStats(const std::vector<ImuSample>& samples, Time start) {
  WindowStats w;
  Eigen::Vector3d sum2_gyro = Eigen::Vector3d::Zero(), sum2_acc = Eigen::Vector3d::Zero();
  for (const ImuSample& s : samples) {
    if (s.t < start || !finiteSample(s)) continue;
    if (w.count == 0) w.first = s.t;
    w.last = s.t;
    ++w.count;
    w.mean_gyro += s.omega_imu;
    w.mean_acc += s.acc_imu;
    sum2_gyro += s.omega_imu.cwiseAbs2();
    sum2_acc += s.acc_imu.cwiseAbs2();
    if (!s.q_world_imu || !s.q_world_imu->coeffs().allFinite()) {
      w.all_oriented = false;
      continue;
    }
    const Eigen::Vector4d q = s.q_world_imu->normalized().coeffs();
    if (w.count == 1) w.q_first = q;
    w.q_sum += (w.q_sum.dot(q) < 0 ? -q : q);  // q and -q are the same rotation
  }
  if (w.count == 0) return w;
  const double n = static_cast<double>(w.count);
  w.mean_gyro /= n;
  w.mean_acc /= n;
  // Population variance; clamp the rounding of E[x^2] - E[x]^2 at 0.
  w.gyro_std = std::sqrt(std::max(0.0, (sum2_gyro / n - w.mean_gyro.cwiseAbs2()).sum()));
  w.acc_std = std::sqrt(std::max(0.0, (sum2_acc / n - w.mean_acc.cwiseAbs2()).sum()));
  return w;
}

// Reasons the window is not static; empty when it is.
std::string staticFailures(const WindowStats& w, const StaticInitializer::Config& c) {
  std::ostringstream out;
  if (w.gyro_std > c.max_gyro_std) out << "gyro std " << w.gyro_std << " rad/s > " << c.max_gyro_std << "; ";
  if (w.acc_std > c.max_acc_std) out << "acc std " << w.acc_std << " m/s^2 > " << c.max_acc_std << "; ";
  if (w.mean_gyro.norm() > c.max_gyro_mean) {
    out << "mean rate " << w.mean_gyro.norm() << " rad/s > " << c.max_gyro_mean << "; ";
  }
  const double g_error = std::abs(w.mean_acc.norm() - c.gravity);
  if (g_error > c.max_gravity_error) {
    out << "| |mean acc| - gravity | = " << g_error << " m/s^2 > " << c.max_gravity_error << "; ";
  }
  return out.str();
}

}  // namespace

Eigen::Quaterniond attitudeFromGravity(const Eigen::Vector3d& f_imu) {
  // At rest f = R^T (0, 0, g) = g (-sin p, sin r cos p, cos r cos p) for R = Rz(0) Ry(p) Rx(r).
  const double roll = std::atan2(f_imu.y(), f_imu.z());
  const double pitch = std::atan2(-f_imu.x(), std::hypot(f_imu.y(), f_imu.z()));
  const Eigen::Quaterniond q = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
  return q.normalized();
}

std::string StaticInitializer::Config::validate() const {
  std::ostringstream out;
  const auto positive = [&out](const char* name, double value) {
    if (!std::isfinite(value) || value <= 0) out << name << " = " << value << " must be finite and > 0; ";
  };
  positive("window_s", window_s);
  positive("max_gyro_std", max_gyro_std);
  positive("max_acc_std", max_acc_std);
  positive("max_gyro_mean", max_gyro_mean);
  positive("max_gravity_error", max_gravity_error);
  positive("gravity", gravity);
  if (!(min_coverage > 0 && min_coverage <= 1)) out << "min_coverage = " << min_coverage << " must be in (0, 1]; ";
  return out.str();
}

StaticInitializer::StaticInitializer() : StaticInitializer(Config{}) {}

StaticInitializer::StaticInitializer(const Config& config) : config_(config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("StaticInitializer::Config: " + error);
}

StaticInitializer::Result StaticInitializer::initialize(const std::vector<ImuSample>& samples) const {
  Result result;
  if (samples.empty()) {
    result.reason = "no IMU samples";
    return result;
  }
  const WindowStats w = windowStats(samples, samples.back().t - fromSeconds(config_.window_s));
  const double span = toSeconds(w.last - w.first);
  if (w.count < 2 || span < config_.min_coverage * config_.window_s || w.mean_acc.norm() <= 0) {
    std::ostringstream out;
    out << "not enough IMU data: " << w.count << " finite samples over " << span << " s, need "
        << config_.min_coverage * config_.window_s << " s";
    result.reason = out.str();
    return result;
  }
  result.ok = true;
  result.samples_used = w.count;
  result.gyro_std = w.gyro_std;
  result.acc_std = w.acc_std;
  result.gravity_magnitude = w.mean_acc.norm();
  result.mean_specific_force = w.mean_acc;
  result.window_end = w.last;
  result.q_world_imu = attitudeFromGravity(w.mean_acc);
  result.reason = staticFailures(w, config_);
  result.is_static = result.reason.empty();
  if (config_.use_orientation && w.all_oriented && w.q_sum.norm() > 0) {
    // At rest the window's mean orientation averages the unit's noise. In motion the orientation turns through
    // the window and its mean is the attitude of no instant: kitti05-replay's car, pitching and turning in its
    // first second, got a start attitude 0.46 deg off in tilt that way, and the map inherited the slope (0.5 m
    // of height in the first 50 m). The first sample's own orientation is the attitude at the window's start.
    result.q_world_imu.coeffs() = result.is_static ? w.q_sum.normalized() : w.q_first;
    result.used_orientation = true;
    const Eigen::Vector3d up = result.q_world_imu * w.mean_acc.normalized();
    result.tilt_mismatch = std::acos(std::clamp(up.z(), -1.0, 1.0));
  }
  if (result.is_static) result.bias.gyro = w.mean_gyro;
  return result;
}

}  // namespace drover::imu
