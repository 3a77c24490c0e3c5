#pragma once
// Drives a SlidingWindowEstimator over a WindowScene: IMU at 200 Hz, camera frames at `camera_hz`.
#include <functional>
#include <vector>

#include "vio/sliding_window.hpp"
#include "vio/window_scene.hpp"

namespace drover::vio::test {

struct WindowRun {
  explicit WindowRun(const WindowScene& s) : scene(s) {}
  const WindowScene& scene;
  double camera_hz = 15;
  double imu_hz = 200;
  double t_imu = 0;  // [s] next IMU sample
  // Edits the features of each frame (drop some, add lidar depth...), given the frame time [s].
  std::function<void(double, std::vector<FrameFeature>&)> edit;

  // Feeds IMU up to and including t, then the frame at t [s]; returns the estimator's result.
  FrameResult frame(SlidingWindowEstimator& est, double t, const Seeder& seed, double camera_delay = 0) {
    for (; t_imu <= t + 1e-9; t_imu += 1.0 / imu_hz) est.addImu(scene.imu(t_imu));
    std::vector<FrameFeature> f = scene.features(t);
    if (edit) edit(t, f);
    return est.addFrame(fromSeconds(t - camera_delay), f, seed);
  }
};

// A seed from the ground truth with zero biases (the window must find them) and the velocity off by dv.
inline Seeder truthSeeder(const WindowScene& scene, const Eigen::Vector3d& dv = Eigen::Vector3d::Zero()) {
  return [&scene, dv](Time t) -> std::optional<SeedState> {
    const SceneTruth tr = scene.truth(toSeconds(t));
    SeedState s;
    s.T_world_imu = tr.T_world_imu;
    s.v_world = tr.v_world + dv;
    return s;
  };
}

}  // namespace drover::vio::test
