#include "sim/trajectory.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace drover::sim {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Wraps an angle into (-pi, pi].
double wrapAngle(double a) {
  a = std::remainder(a, kTwoPi);  // [-pi, pi]
  return a <= -std::numbers::pi ? a + kTwoPi : a;
}

// Quintic smoothstep s(x) = 6x^5 - 15x^4 + 10x^3 on [0, 1], clamped outside, with s' and s'' (w.r.t. x).
struct Smoothstep {
  double s, ds, dds;
};
Smoothstep smoothstep(double x) {
  if (x <= 0.0) return {0.0, 0.0, 0.0};
  if (x >= 1.0) return {1.0, 0.0, 0.0};
  const double y = 1.0 - x;
  return {x * x * x * (10.0 + x * (6.0 * x - 15.0)), 30.0 * x * x * y * y, 60.0 * x * y * (1.0 - 2.0 * x)};
}

void checkVibration(const Vibration& v) {
  const auto bad = [](const std::string& what) {
    throw std::invalid_argument("SplineTrajectory: invalid vibration, " + what);
  };
  if (!std::isfinite(v.amplitude) || !std::isfinite(v.frequency) || !std::isfinite(v.phase))
    bad("non-finite amplitude/frequency/phase");
  if (v.frequency < 0) bad("frequency " + std::to_string(v.frequency) + " < 0");
  if (v.end <= v.start) bad("end " + std::to_string(v.end) + " <= start " + std::to_string(v.start));
  if (v.ramp <= 0) bad("ramp " + std::to_string(v.ramp) + " <= 0");
}

void checkSamples(const std::vector<PathSample>& samples) {
  if (samples.size() < 4)
    throw std::invalid_argument("SplineTrajectory: need at least 4 samples, got " + std::to_string(samples.size()));
  const Time spacing = samples[1].t - samples[0].t;
  if (spacing <= 0)
    throw std::invalid_argument("SplineTrajectory: sample spacing " + std::to_string(spacing) + " ns <= 0");
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const PathSample& s = samples[i];
    if (i > 0 && s.t - samples[i - 1].t != spacing)
      throw std::invalid_argument("SplineTrajectory: samples not uniformly spaced: sample " + std::to_string(i) +
                                  " at " + std::to_string(s.t) + " ns, expected " +
                                  std::to_string(samples[i - 1].t + spacing));
    if (!s.p_world.allFinite() || !std::isfinite(s.yaw) || !std::isfinite(s.pitch) || !std::isfinite(s.roll))
      throw std::invalid_argument("SplineTrajectory: non-finite value in sample " + std::to_string(i));
  }
}

// Rz(yaw) * Ry(pitch) * Rx(roll), multiplied out, from the angles' sines and cosines.
Eigen::Matrix3d rotationFromSinCos(double sy, double cy, double sp, double cp, double sr, double cr) {
  Eigen::Matrix3d R;
  R << cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr,  //
      sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr,   //
      -sp, cp * sr, cp * cr;
  return R;
}
}  // namespace

Eigen::Matrix3d rotationFromEuler(double yaw, double pitch, double roll) {
  return rotationFromSinCos(std::sin(yaw), std::cos(yaw), std::sin(pitch), std::cos(pitch), std::sin(roll),
                            std::cos(roll));
}

Eigen::Vector3d eulerFromRotation(const Eigen::Matrix3d& R) {
  const double pitch = std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2)));
  return {std::atan2(R(1, 0), R(0, 0)), pitch, std::atan2(R(2, 1), R(2, 2))};
}

SplineTrajectory::SplineTrajectory(const std::vector<PathSample>& samples, std::vector<Vibration> vibrations)
    : vibrations_(std::move(vibrations)) {
  checkSamples(samples);
  for (const Vibration& v : vibrations_) checkVibration(v);
  t0_ = samples.front().t;
  spacing_ = samples[1].t - samples[0].t;
  const std::size_t n = samples.size();
  segments_ = n - 1;
  std::vector<Vector6d> y(n);
  for (std::size_t j = 0; j < n; ++j) {
    y[j] << samples[j].p_world, samples[j].yaw, samples[j].pitch, samples[j].roll;
  }
  // Interpolation at knot j: (c_{j-1} + 4 c_j + c_{j+1}) / 6 = y_j, j = 0..n-1, unknowns c_{-1}..c_n.
  // Not-a-knot at knot 1 (fourth difference c_{-1} - 4c_0 + 6c_1 - 4c_2 + c_3 = 0) combined with the equations
  // of knots 0, 1, 2 gives c_1 = (8 y_1 - y_0 - y_2) / 6 (the blossom of the cubic through y_0..y_3 at (0,1,2));
  // symmetrically for c_{n-2}. The rest is a tridiagonal system in c_2..c_{n-3}, then c_0, c_{-1}, c_{n-1}, c_n
  // follow from the equations of knots 1, 0, n-2, n-1.
  ctrl_.assign(n + 2, Vector6d::Zero());
  const auto c = [this](std::ptrdiff_t j) -> Vector6d& { return ctrl_[static_cast<std::size_t>(j + 1)]; };
  const auto ni = static_cast<std::ptrdiff_t>(n);
  c(1) = (8.0 * y[1] - y[0] - y[2]) / 6.0;
  c(ni - 2) = (8.0 * y[n - 2] - y[n - 1] - y[n - 3]) / 6.0;
  // Thomas algorithm for rows j = 2..n-3 of [1 4 1] (strictly diagonally dominant: stable without pivoting).
  const std::size_t m = n - 4;
  std::vector<double> cp(m);
  std::vector<Vector6d> dp(m);
  for (std::size_t k = 0; k < m; ++k) {  // forward sweep, row j = k + 2
    Vector6d d = 6.0 * y[k + 2];
    if (k == 0) d -= c(1);
    if (k + 1 == m) d -= c(ni - 2);
    const double denom = 4.0 - (k > 0 ? cp[k - 1] : 0.0);
    cp[k] = 1.0 / denom;
    dp[k] = (k > 0 ? Vector6d(d - dp[k - 1]) : d) / denom;
  }
  for (std::size_t k = m; k-- > 0;) {  // back substitution
    const auto j = static_cast<std::ptrdiff_t>(k) + 2;
    c(j) = k + 1 < m ? Vector6d(dp[k] - cp[k] * c(j + 1)) : dp[k];
  }
  c(0) = 6.0 * y[1] - 4.0 * c(1) - c(2);
  c(-1) = 6.0 * y[0] - 4.0 * c(0) - c(1);
  c(ni - 1) = 6.0 * y[n - 2] - 4.0 * c(ni - 2) - c(ni - 3);
  c(ni) = 6.0 * y[n - 1] - 4.0 * c(ni - 1) - c(ni - 2);
}

Time SplineTrajectory::startTime() const { return t0_; }
Time SplineTrajectory::endTime() const { return t0_ + static_cast<Time>(segments_) * spacing_; }
Time SplineTrajectory::knotSpacing() const { return spacing_; }

SplineTrajectory::Channels SplineTrajectory::evalSpline(Time t) const {
  const Time rel = t - t0_;
  std::size_t i = static_cast<std::size_t>(rel / spacing_);
  if (i >= segments_) i = segments_ - 1;  // t == end belongs to the last segment (u = 1)
  const double u = static_cast<double>(rel - static_cast<Time>(i) * spacing_) / static_cast<double>(spacing_);
  const double h = toSeconds(spacing_);
  // Uniform cubic B-spline basis on c_{i-1}..c_{i+2} and its u-derivatives (e.g. Qin, "General matrix
  // representations for B-splines", 2000, Eq. 7 for k = 4).
  const double v = 1.0 - u, u2 = u * u, u3 = u2 * u;
  const double b[4] = {v * v * v / 6.0, (3.0 * u3 - 6.0 * u2 + 4.0) / 6.0, (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) / 6.0,
                       u3 / 6.0};
  const double db[4] = {-0.5 * v * v, 0.5 * (3.0 * u2 - 4.0 * u), 0.5 * (-3.0 * u2 + 2.0 * u + 1.0), 0.5 * u2};
  const double ddb[4] = {v, 3.0 * u - 2.0, 1.0 - 3.0 * u, u};
  Channels out{Vector6d::Zero(), Vector6d::Zero(), Vector6d::Zero()};
  for (int k = 0; k < 4; ++k) {
    const Vector6d& p = ctrl_[i + static_cast<std::size_t>(k)];
    out.value += b[k] * p;
    out.rate += db[k] * p;
    out.accel += ddb[k] * p;
  }
  out.rate /= h;
  out.accel /= h * h;
  return out;
}

void SplineTrajectory::addVibrations(Time t, Channels& c) const {
  for (const Vibration& vib : vibrations_) {
    if (t <= vib.start || t >= vib.end) continue;  // the envelope and its derivatives vanish there
    const double ramp = toSeconds(vib.ramp);
    const Smoothstep up = smoothstep(static_cast<double>(t - vib.start) / static_cast<double>(vib.ramp));
    const Smoothstep down = smoothstep(static_cast<double>(vib.end - t) / static_cast<double>(vib.ramp));
    // envelope e = up(t) * down(t); d/dt of the down argument is -1/ramp.
    const double e = up.s * down.s;
    const double de = (up.ds * down.s - up.s * down.ds) / ramp;
    const double dde = (up.dds * down.s - 2.0 * up.ds * down.ds + up.s * down.dds) / (ramp * ramp);
    const double w = kTwoPi * vib.frequency;
    const double arg = w * toSeconds(t - vib.start) + vib.phase;
    const double s = std::sin(arg), co = std::cos(arg);
    const int ch = vib.axis == Vibration::Axis::kZ ? 2 : (vib.axis == Vibration::Axis::kPitch ? 4 : 5);
    c.value[ch] += vib.amplitude * e * s;
    c.rate[ch] += vib.amplitude * (de * s + e * w * co);
    c.accel[ch] += vib.amplitude * (dde * s + 2.0 * de * w * co - e * w * w * s);
  }
}

BodyState SplineTrajectory::at(Time t) const {
  if (t < t0_ || t > endTime())
    throw std::out_of_range("SplineTrajectory::at: t = " + std::to_string(t) + " ns outside [" +
                            std::to_string(t0_) + ", " + std::to_string(endTime()) + "]");
  Channels c = evalSpline(t);
  if (!vibrations_.empty()) addVibrations(t, c);
  const double yaw = c.value[3], pitch = c.value[4], roll = c.value[5];
  const double dyaw = c.rate[3], dpitch = c.rate[4], droll = c.rate[5];
  const double sp = std::sin(pitch), cp = std::cos(pitch), sr = std::sin(roll), cr = std::cos(roll);
  BodyState s;
  s.t = t;
  s.T_world_body.linear() = rotationFromSinCos(std::sin(yaw), std::cos(yaw), sp, cp, sr, cr);
  s.T_world_body.translation() = c.value.head<3>();
  s.v_world = c.rate.head<3>();
  s.a_world = c.accel.head<3>();
  // Body-frame angular velocity of R = Rz(yaw) Ry(pitch) Rx(roll): omega_body = R^T omega_world, i.e.
  // roll' e_x + Rx^T (pitch' e_y) + Rx^T Ry^T (yaw' e_z) (Siciliano et al., Robotics, 2009, Sec. 3.6).
  s.omega_body = {droll - dyaw * sp, dpitch * cr + dyaw * cp * sr, -dpitch * sr + dyaw * cp * cr};
  return s;
}

Eigen::Isometry3d SplineTrajectory::pose(Time t) const { return at(t).T_world_body; }

Trajectory SplineTrajectory::sample(double rate_hz) const {
  if (!(rate_hz > 0) || !std::isfinite(rate_hz))
    throw std::invalid_argument("SplineTrajectory::sample: rate_hz " + std::to_string(rate_hz) + " must be > 0");
  Trajectory out;
  const Time end = endTime();
  for (std::int64_t k = 0;; ++k) {
    const Time t = t0_ + static_cast<Time>(std::llround(static_cast<double>(k) * 1e9 / rate_hz));
    if (t > end) break;
    out.push_back({t, at(t).T_world_body});
  }
  return out;
}

double SplineTrajectory::pathLength() const {
  constexpr Time kStep = 10'000'000;  // [ns] 100 Hz
  double length = 0.0;
  const Time end = endTime();
  for (Time a = t0_; a < end; a += kStep) {
    const Time b = std::min(a + kStep, end);
    const Time mid = a + (b - a) / 2;
    length += toSeconds(b - a) / 6.0 *
              (at(a).v_world.norm() + 4.0 * at(mid).v_world.norm() + at(b).v_world.norm());
  }
  return length;
}

std::vector<PathSample> SplineTrajectory::resample(const std::vector<PathSample>& keyframes, Time spacing) {
  if (spacing <= 0)
    throw std::invalid_argument("SplineTrajectory::resample: spacing " + std::to_string(spacing) + " ns <= 0");
  if (keyframes.size() < 2)
    throw std::invalid_argument("SplineTrajectory::resample: need at least 2 keyframes, got " +
                                std::to_string(keyframes.size()));
  std::vector<PathSample> keys = keyframes;
  for (std::size_t i = 1; i < keys.size(); ++i) {
    if (keys[i].t <= keys[i - 1].t)
      throw std::invalid_argument("SplineTrajectory::resample: keyframe " + std::to_string(i) + " at " +
                                  std::to_string(keys[i].t) + " ns not after " + std::to_string(keys[i - 1].t));
    keys[i].yaw = keys[i - 1].yaw + wrapAngle(keys[i].yaw - keys[i - 1].yaw);
  }
  std::vector<PathSample> out;
  std::size_t seg = 0;
  for (Time t = keys.front().t; t <= keys.back().t; t += spacing) {
    while (seg + 2 < keys.size() && t > keys[seg + 1].t) ++seg;
    const PathSample& a = keys[seg];
    const PathSample& b = keys[seg + 1];
    const double alpha = static_cast<double>(t - a.t) / static_cast<double>(b.t - a.t);
    PathSample s;
    s.t = t;
    s.p_world = a.p_world + alpha * (b.p_world - a.p_world);
    s.yaw = a.yaw + alpha * (b.yaw - a.yaw);
    s.pitch = a.pitch + alpha * (b.pitch - a.pitch);
    s.roll = a.roll + alpha * (b.roll - a.roll);
    out.push_back(s);
  }
  return out;
}

std::vector<PathSample> SplineTrajectory::fromPoses(const Trajectory& poses) {
  std::vector<PathSample> out;
  out.reserve(poses.size());
  for (const StampedPose& pose : poses) {
    const Eigen::Vector3d e = eulerFromRotation(pose.T_world_body.linear());
    PathSample s;
    s.t = pose.t;
    s.p_world = pose.T_world_body.translation();
    s.yaw = out.empty() ? e[0] : out.back().yaw + wrapAngle(e[0] - out.back().yaw);
    s.pitch = e[1];
    s.roll = e[2];
    out.push_back(s);
  }
  return out;
}

}  // namespace drover::sim
