#pragma once
// A synthetic place with exact geometry for loop-closure tests: LOAM-like features of a walled courtyard (ground
// and four walls of different heights as plane points, five poles as edge points), in its own world frame, and what a
// lidar at a given pose sees of it (every point, no occlusion).
#include <Eigen/Geometry>
#include <random>

#include "lidar/feature_set.hpp"

namespace drover::test {

// `variant` moves the walls and poles to make another place.
inline lidar::FeatureSet courtyard(int variant) {
  lidar::FeatureSet f;
  std::mt19937 rng(42 + variant);
  std::uniform_real_distribution<float> u(-1, 1);
  const float w = 12.0f + 3.0f * variant, l = 9.0f + 4.0f * variant;
  for (float x = -w; x <= w; x += 0.4f)
    for (float y = -l; y <= l; y += 0.4f) f.planes.emplace_back(x, y, -1.8f + 0.002f * u(rng));
  // Walls and poles of different heights, so the place looks different from different spots (Scan Context).
  for (float s = -1; s <= 1; s += 0.02f) {
    for (float z = -1.8f; z <= 1.2f; z += 0.4f) f.planes.emplace_back(w, s * l, z);
    for (float z = -1.8f; z <= 3.0f; z += 0.4f) f.planes.emplace_back(-w, s * l * 0.8f, z);
    for (float z = -1.8f; z <= 0.4f; z += 0.4f) f.planes.emplace_back(s * w, l, z);
    for (float z = -1.8f; z <= 4.2f; z += 0.4f) f.planes.emplace_back(s * w * 0.7f, -l, z);
  }
  const Eigen::Vector3f poles[] = {{4, 3, 2.0f}, {-5, 2, 5.0f}, {6, -4, 1.0f}, {-3, -6, 3.5f}, {1, 7, 0.5f}};
  for (const Eigen::Vector3f& p : poles)
    for (float z = -1.8f; z <= p.z(); z += 0.1f) f.edges.emplace_back(p.x() + variant, p.y() - variant, z);
  f.full = f.planes;
  return f;
}

inline lidar::FeatureSet seenFrom(const lidar::FeatureSet& world, const Eigen::Isometry3d& T_world_lidar) {
  const Eigen::Isometry3f T = T_world_lidar.inverse().cast<float>();
  lidar::FeatureSet f;
  for (const auto& p : world.edges) f.edges.push_back(T * p);
  for (const auto& p : world.planes) f.planes.push_back(T * p);
  f.full = f.planes;
  return f;
}

// Planar pose: (x, y) [m], heading [deg].
inline Eigen::Isometry3d planarPose(double x, double y, double yaw_deg) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_deg * 3.14159265358979323846 / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() << x, y, 0.0;
  return T;
}

}  // namespace drover::test
