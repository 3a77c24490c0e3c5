#pragma once
// Test helper: probing a scenario's world from its path with rays.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "sim/scenario.hpp"

namespace drover::sim::probe {

inline double headingOf(const Eigen::Isometry3d& T) { return std::atan2(T.linear()(1, 0), T.linear()(0, 0)); }

// A ray's hit is "ground": a horizontal surface below the body (ground plane, ramp, floor, road).
inline bool isGroundBelow(const Hit& h, const Eigen::Vector3d& origin) {
  return std::abs(h.normal.z()) > 0.9 && h.point.z() < origin.z() - 0.2;
}

// Nearest non-ground surface from the body at t along horizontal, diagonally-up and vertical rays.
inline double nearestObstacle(const Scenario& s, Time t, double limit) {
  const Eigen::Isometry3d T = s.trajectory->pose(t);
  const Eigen::Vector3d o = T.translation();
  const double h = headingOf(T);
  double nearest = limit;
  std::vector<Eigen::Vector3d> dirs = {Eigen::Vector3d::UnitZ()};
  for (int k = 0; k < 8; ++k) {
    const double a = h + k * std::numbers::pi / 4;
    dirs.emplace_back(std::cos(a), std::sin(a), 0.0);
    dirs.push_back(Eigen::Vector3d(std::cos(a), std::sin(a), 1.0).normalized());
  }
  for (const Eigen::Vector3d& d : dirs) {
    const auto hit = s.world.intersect({o, d}, 1e-4, limit);
    if (hit && !isGroundBelow(*hit, o)) nearest = std::min(nearest, hit->distance);
  }
  return nearest;
}

}  // namespace drover::sim::probe
