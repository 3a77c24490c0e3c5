#pragma once
// Small scenes for the simulated camera's tests (tests/sim/test_camera_*.cpp, tests/visual/test_rendered_*.cpp).
#include <Eigen/Geometry>

#include "sim/world.hpp"

namespace drover::test {

// Camera z forward, x right, y down, at the body origin looking along body x (body y left, z up).
inline Eigen::Isometry3d forwardCamera() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  T.linear().col(1) = Eigen::Vector3d(0, 0, -1);
  T.linear().col(2) = Eigen::Vector3d(1, 0, 0);
  return T;
}

// A wall in the plane x = distance facing the origin (normal -x), 2 half_size m square.
inline sim::World wallWorld(double distance, const sim::Material& material, double half_size = 20) {
  sim::Rectangle wall;
  wall.T_world_rect.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  wall.T_world_rect.linear().col(1) = Eigen::Vector3d(0, 0, 1);
  wall.T_world_rect.linear().col(2) = Eigen::Vector3d(-1, 0, 0);
  wall.T_world_rect.translation() = Eigen::Vector3d(distance, 0, 0);
  wall.half_size = Eigen::Vector2d(half_size, half_size);
  sim::World world;
  world.addRectangle(wall, material);
  world.build();
  return world;
}

}  // namespace drover::test
