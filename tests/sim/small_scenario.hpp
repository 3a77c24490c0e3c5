#pragma once
// A small hand-built scenario for the simulator's tests (no scenario catalogue): 2 s at 1 m/s past a brick wall.
#include <cstring>
#include <memory>
#include <vector>

#include "sim/simulator.hpp"

namespace drover::sim::fixture {

// 2 s at 1 m/s along x, a wall 4 m to the left, a ground plane.
inline Scenario smallScenario() {
  Scenario s;
  s.name = "test-straight";
  Material m;
  m.texture = Texture::kBrick;
  m.reflectivity = 0.8f;
  s.world.setGround(0.0, m);
  Box wall;
  wall.T_world_box.translation() = Eigen::Vector3d(1.0, 4.0, 1.0);
  wall.half_extents = Eigen::Vector3d(10.0, 0.2, 1.0);
  s.world.addBox(wall, m);
  s.world.build();
  std::vector<PathSample> samples;
  for (int i = 0; i <= 8; ++i) {
    PathSample p;
    p.t = i * 250'000'000LL;
    p.p_world = Eigen::Vector3d(0.25 * i, 0.0, 0.3);
    samples.push_back(p);
  }
  s.trajectory = std::make_shared<SplineTrajectory>(samples);
  s.illumination = [](Time, const Eigen::Vector3d&) { return 1.0f; };
  s.segments = {{Condition::kStraight, 0, 2'000'000'000}};
  s.max_speed = 1.0;
  return s;
}

// Defaults with a small camera (64x48) so a frame renders in a few milliseconds.
inline SimulatorConfig smallConfig() {
  SimulatorConfig c = SimulatorConfig::defaults();
  CameraIntrinsics& k = c.camera.intrinsics;
  k.width = 64, k.height = 48, k.fx = k.fy = 46.0, k.cx = 31.5, k.cy = 23.5;
  c.lidar.columns = 360;
  return c;
}

inline std::vector<Measurement> runAll(const Simulator& sim, Time chunk = kNanosPerSecond) {
  std::vector<Measurement> out;
  sim.run([&](Measurement&& m) { out.push_back(std::move(m)); }, chunk);
  return out;
}

// Same kind, stamp and bytes.
inline bool sameMeasurement(const Measurement& a, const Measurement& b) {
  if (a.index() != b.index() || measurementTime(a) != measurementTime(b)) return false;
  if (const auto* x = std::get_if<ImuSample>(&a)) {
    const auto& y = std::get<ImuSample>(b);
    return x->omega_imu == y.omega_imu && x->acc_imu == y.acc_imu;
  }
  if (const auto* x = std::get_if<LidarScan>(&a)) {
    const auto& y = std::get<LidarScan>(b);
    if (x->points.size() != y.points.size()) return false;
    for (std::size_t i = 0; i < x->points.size(); ++i)
      if (std::memcmp(&x->points[i], &y.points[i], sizeof(LidarPoint)) != 0) return false;
    return true;
  }
  return std::get<CameraFrame>(a).image.data == std::get<CameraFrame>(b).image.data;
}

}  // namespace drover::sim::fixture
