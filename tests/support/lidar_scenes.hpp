#pragma once
// Exact synthetic lidar geometry for the scan matcher's tests: planes and their edge lines, a map sampled from them at
// identity and a scan that samples the same geometry differently from a known pose T (points mapped by T^-1), so the
// ground truth is exact.
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "geometry/se3.hpp"
#include "lidar/feature_set.hpp"
#include "lidar/local_map.hpp"

namespace drover::test {

using lidar::FeatureSet;
using lidar::LocalMap;
using lidar::LocalMapConfig;

// The rectangle origin + a u + b v, a in [0, lu], b in [0, lv] (u, v orthonormal).
struct Rect {
  Eigen::Vector3d origin, u, v;
  double lu, lv;
};
struct Segment {
  Eigen::Vector3d a, b;
};
struct Scene {
  std::vector<Rect> planes;
  std::vector<Segment> edges;
};

// The six faces and twelve edges of the axis-aligned box [lo, hi].
inline Scene boxRoom(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  Scene s;
  const Eigen::Vector3d d = hi - lo;
  for (int axis = 0; axis < 3; ++axis) {
    const int i = (axis + 1) % 3, j = (axis + 2) % 3;
    const Eigen::Vector3d u = Eigen::Vector3d::Unit(i), v = Eigen::Vector3d::Unit(j);
    for (double side : {0.0, 1.0}) {
      const Eigen::Vector3d origin = lo + side * d[axis] * Eigen::Vector3d::Unit(axis);
      s.planes.push_back({origin, u, v, d[i], d[j]});
      for (double side_i : {0.0, 1.0}) {  // the face's two borders along u; over all faces every box edge twice
        s.edges.push_back({origin + side_i * d[j] * v, origin + side_i * d[j] * v + d[i] * u});
      }
    }
  }
  return s;
}

// Two walls y = +-half_width, floor and ceiling, along x in [-half_length, half_length]: no ends in range.
inline Scene corridor(double half_length, double half_width, double floor_z, double ceiling_z) {
  Scene s;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(), z = Eigen::Vector3d::UnitZ();
  const double L = 2.0 * half_length, W = 2.0 * half_width, H = ceiling_z - floor_z;
  for (double wy : {-half_width, half_width}) s.planes.push_back({{-half_length, wy, floor_z}, x, z, L, H});
  for (double hz : {floor_z, ceiling_z}) s.planes.push_back({{-half_length, -half_width, hz}, x, y, L, W});
  for (double wy : {-half_width, half_width}) {
    for (double hz : {floor_z, ceiling_z}) s.edges.push_back({{-half_length, wy, hz}, {half_length, wy, hz}});
  }
  return s;
}

// Map: planes on a grid of `spacing`, edges every spacing / 4, at identity (world = map lidar frame).
inline FeatureSet sampleMap(const Scene& scene, double spacing) {
  FeatureSet map;
  for (const Rect& r : scene.planes) {
    for (double a = 0.0; a <= r.lu + 1e-9; a += spacing) {
      for (double b = 0.0; b <= r.lv + 1e-9; b += spacing) {
        map.planes.push_back((r.origin + a * r.u + b * r.v).cast<float>());
      }
    }
  }
  for (const Segment& e : scene.edges) {
    const double length = (e.b - e.a).norm();
    for (double a = 0.0; a <= length + 1e-9; a += spacing / 4.0) {
      map.edges.push_back((e.a + a / length * (e.b - e.a)).cast<float>());
    }
  }
  map.full = map.planes;
  return map;
}

// Scan: random points (fixed seed) at least `margin` from plane borders and edge ends, within `range` of the
// scan origin, seen from T_world_lidar (lidar points = T^-1 world points).
inline FeatureSet sampleScan(const Scene& scene, const Eigen::Isometry3d& T_world_lidar, int n_planes, int n_edges,
                      double range, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Isometry3d T_lidar_world = geometry::inverse(T_world_lidar);
  const double margin = 1.0;
  FeatureSet scan;
  std::vector<double> areas;
  double total = 0.0;
  for (const Rect& r : scene.planes) total += (r.lu - 2 * margin) * (r.lv - 2 * margin);
  while (static_cast<int>(scan.planes.size()) < n_planes) {
    double pick = unit(rng) * total;
    for (const Rect& r : scene.planes) {
      const double area = (r.lu - 2 * margin) * (r.lv - 2 * margin);
      if ((pick -= area) > 0.0) continue;
      const Eigen::Vector3d p = r.origin + (margin + unit(rng) * (r.lu - 2 * margin)) * r.u +
                                (margin + unit(rng) * (r.lv - 2 * margin)) * r.v;
      if ((p - T_world_lidar.translation()).norm() < range) scan.planes.push_back((T_lidar_world * p).cast<float>());
      break;
    }
  }
  while (static_cast<int>(scan.edges.size()) < n_edges) {
    const Segment& e = scene.edges[static_cast<std::size_t>(unit(rng) * scene.edges.size()) % scene.edges.size()];
    const double length = (e.b - e.a).norm();
    const Eigen::Vector3d p = e.a + (0.6 + unit(rng) * (length - 1.2)) / length * (e.b - e.a);
    if ((p - T_world_lidar.translation()).norm() < range) scan.edges.push_back((T_lidar_world * p).cast<float>());
  }
  return scan;
}

inline Eigen::Isometry3d poseRpy(const Eigen::Vector3d& t, double roll, double pitch, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = t;
  return T;
}

inline LocalMap buildMap(const FeatureSet& map_features, const LocalMapConfig& config = {}) {
  LocalMap map(config);
  map.addKeyframe(map_features, Eigen::Isometry3d::Identity());
  map.build(Eigen::Vector3d::Zero());
  return map;
}

// Two walls, each turned by `taper` [rad] about z so that the corridor widens along x (y = +-(half_width + x tan
// taper)), floor and ceiling, along x in [-half_length, half_length]. The walls' normals lean sin(taper) along the
// axis: the axis is held, but only as much as a facing wall would hold it with sin^2(taper) of their points.
inline Scene taperedCorridor(double half_length, double half_width, double floor_z, double ceiling_z, double taper) {
  Scene s;
  const double t = std::tan(taper), H = ceiling_z - floor_z, L = 2.0 * half_length;
  const double widest = half_width + half_length * t;
  for (double side : {-1.0, 1.0}) {
    const Eigen::Vector3d start(-half_length, side * (half_width - half_length * t), floor_z);
    const Eigen::Vector3d u = Eigen::Vector3d(1.0, side * t, 0.0).normalized();
    s.planes.push_back({start, u, Eigen::Vector3d::UnitZ(), L * std::sqrt(1.0 + t * t), H});
    for (double hz : {floor_z, ceiling_z}) {
      const Eigen::Vector3d a(start.x(), start.y(), hz);
      s.edges.push_back({a, a + L * std::sqrt(1.0 + t * t) * u});
    }
  }
  for (double hz : {floor_z, ceiling_z})
    s.planes.push_back({{-half_length, -widest, hz}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), L, 2 * widest});
  return s;
}

}  // namespace drover::test
