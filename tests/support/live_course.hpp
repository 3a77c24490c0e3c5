#pragma once
// Simulated courses for the live system's tests (tests/pipeline/test_system*.cpp): the measurement stream in time
// order with its calibration and exact truth, the odometry config for the simulated VLP-16, and ways to feed a
// pipeline::System as a sensor stream would.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/system.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace drover::test {

struct LiveCourse {
  std::vector<Measurement> stream;
  Calibration calibration;
  Trajectory truth;  // T_world_imu at 200 Hz, on the IMU's and the sweeps' stamps
};

// faults: windows relative to the scenario's start (as drover sim --fault).
inline LiveCourse simulateLiveCourse(const std::string& name, double duration_s, unsigned seed, bool camera = false,
                                     std::vector<sim::SensorFault> faults = {}) {
  sim::ScenarioOptions so;
  so.duration_s = duration_s;
  const sim::Scenario scenario = sim::makeScenario(name, so);
  sim::SimulatorConfig config = sim::SimulatorConfig::defaults();
  config.enable_camera = camera;
  for (sim::SensorFault& f : faults) {
    f.start += scenario.trajectory->startTime();
    f.end += scenario.trajectory->startTime();
  }
  config.faults = std::move(faults);
  const sim::Simulator simulator(scenario, config, seed);
  LiveCourse c;
  simulator.run([&](Measurement&& m) { c.stream.push_back(std::move(m)); });
  c.calibration = simulator.calibration();
  c.truth = simulator.groundTruth();
  return c;
}

// The simulated VLP-16 sees the robot's own body within 0.8 m; the sharp-turns course's walls are near.
inline pipeline::OdometryConfig simOdometryConfig() {
  pipeline::OdometryConfig c;
  c.layout.min_range = c.features.min_range = 0.8;
  c.features.surf_leaf = 0.2f;
  c.local_map.plane_leaf = 0.2;
  return c;
}

inline void pushMeasurement(pipeline::System& system, const Measurement& m) {
  if (const auto* imu = std::get_if<ImuSample>(&m)) system.pushImu(*imu);
  else if (const auto* scan = std::get_if<LidarScan>(&m)) system.pushSweep(*scan);
  else system.pushFrame(std::get<CameraFrame>(m));
}

// As a sensor stream with a LIS that keeps up: before each sweep, every sweep pushed before has been processed or
// dropped, except the newest (which waits for the IMU to cover its end), or a sweep period [100 ms] has passed (the
// first sweeps wait for the IMU initialisation window; a skipped sweep never comes). `processed` counts the System's
// sweep callbacks. Without this, seconds of data go in within milliseconds and the queue drops them.
inline void feedAsInRealTime(pipeline::System& system, const std::vector<Measurement>& stream,
                             const std::atomic<std::size_t>& processed) {
  for (const Measurement& m : stream) {
    if (std::holds_alternative<LidarScan>(m)) {
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
      for (;;) {
        const pipeline::SystemStats s = system.stats();
        if (processed.load() + s.sweeps_dropped + 1 >= s.sweeps_pushed || std::chrono::steady_clock::now() > deadline)
          break;
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    }
    pushMeasurement(system, m);
  }
}

// The truth at exactly t (the simulator stamps the IMU and the sweeps on the truth's grid), or nullptr.
inline const Eigen::Isometry3d* truthAt(const Trajectory& truth, Time t) {
  const auto it =
      std::lower_bound(truth.begin(), truth.end(), t, [](const StampedPose& p, Time x) { return p.t < x; });
  return it != truth.end() && it->t == t ? &it->T_world_body : nullptr;
}

// The transform putting the LIS's per-sweep IMU poses into the truth's frame by their first sweep (the odometry's
// world is that sweep's gravity-aligned frame), or nothing without a truth there.
inline std::optional<Eigen::Isometry3d> alignedByFirstSweep(const Trajectory& sweeps, const LiveCourse& course) {
  if (sweeps.empty()) return std::nullopt;
  const Eigen::Isometry3d* start = truthAt(course.truth, sweeps.front().t);
  if (start == nullptr) return std::nullopt;
  return *start * (sweeps.front().T_world_body * course.calibration.T_imu_lidar.inverse()).inverse();
}

// The position error [m] of one per-sweep pose under that alignment; 1e9 without a truth at its stamp.
inline double sweepError(const StampedPose& p, const Eigen::Isometry3d& T_truth_est, const LiveCourse& course) {
  const Eigen::Isometry3d* truth = truthAt(course.truth, p.t);
  if (truth == nullptr) return 1e9;
  return ((T_truth_est * p.T_world_body * course.calibration.T_imu_lidar.inverse()).translation() -
          truth->translation()).norm();
}

// The largest position error [m] of the LIS's per-sweep IMU poses from `first` on, aligned by their first sweep.
inline double worstSweepError(const Trajectory& sweeps, const LiveCourse& course, Time first = 0) {
  const std::optional<Eigen::Isometry3d> T_truth_est = alignedByFirstSweep(sweeps, course);
  if (!T_truth_est) return 1e9;
  double worst = 0;
  for (const StampedPose& p : sweeps) {
    if (p.t < first || truthAt(course.truth, p.t) == nullptr) continue;
    worst = std::max(worst, sweepError(p, *T_truth_est, course));
  }
  return worst;
}

// The same at the sweep nearest t [m].
inline double sweepErrorAt(const Trajectory& sweeps, const LiveCourse& course, Time t) {
  const std::optional<Eigen::Isometry3d> T_truth_est = alignedByFirstSweep(sweeps, course);
  if (!T_truth_est) return 1e9;
  const auto nearest = std::min_element(sweeps.begin(), sweeps.end(), [t](const StampedPose& a, const StampedPose& b) {
    return std::abs(a.t - t) < std::abs(b.t - t);
  });
  return sweepError(*nearest, *T_truth_est, course);
}

}  // namespace drover::test
