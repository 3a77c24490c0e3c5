#pragma once
// The start of the simulated sharp-turns course for lidar-inertial tests: at rest for 2.5 s, an 11 m straight, then
// turning at ~19 deg/s from 13.5 s; VLP-16 and IMU (simulator seed 7), no camera; with the LIS settings these tests
// run it with and a lookup of its 200 Hz ground truth.
#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

#include "pipeline/lidar_odometry.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace drover::test {

struct SharpTurnsCourse {
  std::vector<Measurement> stream;  // time-ordered, from `from_s` on
  Calibration calibration;
  Trajectory truth;  // T_world_imu at 200 Hz, on the IMU's and the sweeps' stamps
};

// The course's first duration_s seconds; the measurements before from_s [s] are dropped (a start in motion).
inline SharpTurnsCourse sharpTurnsCourse(double duration_s, double from_s = 0.0) {
  sim::ScenarioOptions so;
  so.duration_s = duration_s;
  const sim::Scenario scenario = sim::makeScenario("sharp-turns", so);
  sim::SimulatorConfig config = sim::SimulatorConfig::defaults();
  config.enable_camera = false;
  const sim::Simulator simulator(scenario, config, 7);
  SharpTurnsCourse out;
  simulator.run([&](Measurement&& m) {
    if (measurementTime(m) >= fromSeconds(from_s)) out.stream.push_back(std::move(m));
  });
  out.calibration = simulator.calibration();
  out.truth = simulator.groundTruth();
  return out;
}

// The LIS settings these tests run the course with: a 0.8 m minimum range and 0.2 m plane leaves.
inline pipeline::OdometryConfig sharpTurnsOdometryConfig() {
  pipeline::OdometryConfig c;
  c.layout.min_range = c.features.min_range = 0.8;
  c.features.surf_leaf = 0.2f;
  c.local_map.plane_leaf = 0.2;
  return c;
}

// Iterator to the first truth sample at or after t (end() when none).
inline Trajectory::const_iterator truthFrom(const Trajectory& truth, Time t) {
  return std::lower_bound(truth.begin(), truth.end(), t, [](const StampedPose& p, Time x) { return p.t < x; });
}

}  // namespace drover::test
