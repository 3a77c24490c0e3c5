#pragma once
// Shared ground truth for the imu tests: analytic simulator trajectories and their noise-free IMU.
#include <cmath>
#include <functional>
#include <vector>

#include "imu/preintegration.hpp"
#include "sim/imu_model.hpp"
#include "sim/trajectory.hpp"

namespace drover::imu::testing {

constexpr Time kSec = 1'000'000'000;
constexpr double kDeg = 3.14159265358979323846 / 180.0;

inline sim::SplineTrajectory splineOf(const std::function<sim::PathSample(double)>& f, Time spacing, int count,
                                      std::vector<sim::Vibration> vibrations = {}) {
  std::vector<sim::PathSample> samples;
  for (int k = 0; k < count; ++k) {
    sim::PathSample s = f(toSeconds(k * spacing));
    s.t = k * spacing;
    samples.push_back(s);
  }
  return sim::SplineTrajectory(samples, std::move(vibrations));
}

// Turning, climbing and jolting at once over 4 s (as tests/sim/test_imu_model.cpp): vibrations on z (12 Hz),
// pitch (9 Hz) and roll (7 Hz) at full amplitude over [0.8, 3.2] s.
inline sim::SplineTrajectory demandingPath() {
  const auto f = [](double t) {
    sim::PathSample s;
    s.p_world = {1.2 * t, 2.0 * std::sin(0.5 * t), 0.15 * t + 0.05 * std::sin(1.5 * t)};
    s.yaw = 0.6 * t + 0.3 * std::sin(t);
    s.pitch = -0.1 + 0.05 * std::sin(0.7 * t);
    s.roll = 0.08 * std::cos(1.3 * t);
    return s;
  };
  using Axis = sim::Vibration::Axis;
  return splineOf(f, kSec / 10, 41,
                  {{Axis::kZ, 0.005, 12.0, 0.2, kSec / 2, 7 * kSec / 2, 3 * kSec / 10},
                   {Axis::kPitch, 0.01, 9.0, 1.1, kSec / 2, 7 * kSec / 2, 3 * kSec / 10},
                   {Axis::kRoll, 0.015, 7.0, -0.4, kSec / 2, 7 * kSec / 2, 3 * kSec / 10}});
}

inline sim::ImuModelConfig noiseFree(double rate_hz) {
  sim::ImuModelConfig c;
  c.rate_hz = rate_hz;
  c.noise = false;
  return c;
}

inline NavState navStateAt(const sim::SplineTrajectory& trajectory, Time t) {
  const sim::BodyState b = trajectory.at(t);
  NavState s;
  s.t = t;
  s.T_world_imu = b.T_world_body;
  s.v_world = b.v_world;
  return s;
}

}  // namespace drover::imu::testing
