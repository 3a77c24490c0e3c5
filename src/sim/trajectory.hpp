#pragma once
// The simulated robot's motion: a C2-continuous analytic trajectory of the body (= IMU) frame in the world,
// with exact first and second derivatives, from which the IMU is computed and at which every lidar column and
// camera frame is rendered. World frame: z up, gravity (0, 0, -9.81) m/s^2.
//
// Representation: uniform cubic B-splines (C2) for position p(t) and for the Z-Y-X Euler angles yaw(t),
// pitch(t), roll(t) (a ground robot never pitches near 90 deg), plus optional analytic vibration terms (sums of
// sinusoids on z, pitch and roll, C-infinity) for the "undulating jolting" scenario. Angular velocity in the body
// frame follows from the Euler rates exactly: omega_body = E(roll, pitch) * [roll', pitch', yaw']
// (e.g. Siciliano et al., Robotics, Eq. 3.64, for the Z-Y-X convention).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "types/time.hpp"
#include "types/trajectory.hpp"

namespace drover::sim {

// The body state at one instant; all exact (analytic), no finite differences.
struct BodyState {
  Time t = 0;                                              // [ns]
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();       // [m/s]
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();       // [m/s^2], kinematic (no gravity)
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();    // [rad/s], body frame
};

// One sample the spline is fitted through: position and Euler angles of the body at time t.
struct PathSample {
  Time t = 0;                         // [ns]
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  // [m]
  double yaw = 0, pitch = 0, roll = 0;                // [rad], Z-Y-X; yaw unwrapped (continuous, no 2 pi jumps)
};

// A sinusoidal vibration added on top of the spline: amplitude * envelope(t) * sin(2 pi f (t - start) + phase),
// with t - start in seconds (phase is measured from the span's start, which keeps sin() accurate at any epoch).
// envelope(t) = s((t - start) / ramp) * s((end - t) / ramp), s(x) the quintic smoothstep 6x^5 - 15x^4 + 10x^3
// clamped to [0, 1] (s, s', s'' vanish at x = 0 and s', s'' at x = 1, so the vibration is C2 everywhere and
// exactly zero outside [start, end]). The constructor throws std::invalid_argument unless end > start,
// ramp > 0, frequency >= 0 and all values are finite.
struct Vibration {
  enum class Axis { kZ, kPitch, kRoll } axis = Axis::kZ;
  double amplitude = 0;   // [m] for kZ, [rad] for kPitch/kRoll
  double frequency = 0;   // [Hz]
  double phase = 0;       // [rad]
  Time start = 0, end = 0;  // [ns] active span; a C2 smoothstep envelope of `ramp` ns at each end keeps C2
  Time ramp = 500'000'000;
};

// R_world_body = Rz(yaw) Ry(pitch) Rx(roll) (Z-Y-X, intrinsic) and its inverse map; eulerFromRotation returns
// (yaw, pitch, roll) with yaw, roll in (-pi, pi] and pitch in [-pi/2, pi/2].
Eigen::Matrix3d rotationFromEuler(double yaw, double pitch, double roll);
Eigen::Vector3d eulerFromRotation(const Eigen::Matrix3d& R_world_body);

class SplineTrajectory {
 public:
  // Fits uniform cubic B-splines through the samples, which are the knots: at least 4, strictly increasing times,
  // all spaced by exactly the same number of nanoseconds (throws std::invalid_argument otherwise). The spline
  // interpolates the samples (control points solved from the tridiagonal interpolation system), so the path
  // passes through them. End conditions: not-a-knot (the third derivative is continuous at the second and the
  // second-to-last knot), so any cubic polynomial in time -- in particular constant velocity and constant
  // acceleration -- is reproduced exactly over the whole span, ends included.
  SplineTrajectory(const std::vector<PathSample>& samples, std::vector<Vibration> vibrations = {});

  // Helper for scenario builders: resamples time-ordered keyframes (any, non-uniform spacing, at least 2, strictly
  // increasing times) onto the uniform grid t_first + k * spacing, k = 0.. while <= t_last, by linear
  // interpolation of position and angles. Yaw is unwrapped first (each step taken modulo 2 pi into (-pi, pi]).
  // The spline through the result rounds the keyframes' corners on the scale of `spacing`: for sparse waypoints
  // choose a spacing near their own (a fine grid through a polyline makes large accelerations at its corners).
  // Throws std::invalid_argument for spacing <= 0, fewer than 2 keyframes or unordered times.
  static std::vector<PathSample> resample(const std::vector<PathSample>& keyframes, Time spacing);
  // Poses (T_world_body, time-ordered) to PathSamples with Z-Y-X angles and yaw unwrapped; feed to resample().
  static std::vector<PathSample> fromPoses(const Trajectory& poses);

  Time startTime() const;
  Time endTime() const;
  Time knotSpacing() const;  // [ns]
  // Exact state at t in [startTime(), endTime()]; throws std::out_of_range outside. O(1), allocation-free
  // (direct segment index from t), ~the cost of a few dozen multiply-adds plus the trigonometry.
  BodyState at(Time t) const;
  Eigen::Isometry3d pose(Time t) const;
  // Ground truth at `rate_hz` over the whole span (TUM-ready T_world_body): t_k = start + round(k * 1e9 / rate_hz)
  // for every k with t_k <= end (both ends included where they fall on that grid). Throws for rate_hz <= 0.
  Trajectory sample(double rate_hz) const;
  // Path length [m], by integrating |v| at 100 Hz (Simpson's rule on each 10 ms step; the last step is shorter).
  double pathLength() const;

 private:
  // Channels of the spline: x, y, z [m], yaw, pitch, roll [rad].
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  struct Channels {
    Vector6d value, rate, accel;  // value and its first two time derivatives [unit, unit/s, unit/s^2]
  };
  Channels evalSpline(Time t) const;
  void addVibrations(Time t, Channels& c) const;

  Time t0_ = 0, spacing_ = 0;     // [ns] first knot and knot spacing
  std::size_t segments_ = 0;       // number of knot intervals (samples - 1)
  // B-spline control points c_{-1} .. c_{N}: ctrl_[k] = c_{k-1}; segment i uses ctrl_[i .. i+3].
  std::vector<Vector6d> ctrl_;
  std::vector<Vibration> vibrations_;
};

}  // namespace drover::sim
