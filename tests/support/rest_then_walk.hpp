#pragma once
// A test path along x: at rest for 1 s, 0.5 m/s^2 up to 1 m/s by 3 s, then 1 m/s (spline knots every 0.5 s up to
// `seconds`), and the exact IMU along a path. Shared by the tests of the LIS's IMU fusion that drive it with exact
// sensors.
#include <vector>

#include "sim/imu_model.hpp"
#include "sim/trajectory.hpp"
#include "support/units.hpp"

namespace drover::test {

inline sim::SplineTrajectory restThenWalk(int seconds) {
  std::vector<sim::PathSample> knots;
  for (int k = 0; k <= 2 * seconds; ++k) {
    const double t = 0.5 * k;
    sim::PathSample s;
    s.t = k * kSec / 2;
    s.p_world.x() = t <= 1 ? 0.0 : t <= 3 ? 0.25 * (t - 1) * (t - 1) : 1.0 + (t - 3);
    knots.push_back(s);
  }
  return sim::SplineTrajectory(knots);
}

// The IMU along `path` without noise or biases (the simulator's default rates).
inline std::vector<ImuSample> exactImu(const sim::SplineTrajectory& path) {
  sim::ImuModelConfig m;
  m.noise = false;
  return sim::simulateImu(path, m, 1);
}

}  // namespace drover::test
