#pragma once
// The LIS's path length over time: a running sum of the distances between its fused states. The VIS's keyframe gate
// asks how far the robot went since the VIS's last keyframe, not only how long ago that was: a robot that stood
// still has no keyframe due however long it stood (pipeline/visual_motion.hpp, keyframe_gap_min_distance).
#include <Eigen/Geometry>
#include <deque>
#include <optional>
#include <utility>

#include "types/time.hpp"

namespace drover::pipeline {

class PathOdometer {
 public:
  // One state at t in the world frame; a t not after the newest is ignored.
  void add(Time t, const Eigen::Vector3d& p_world);
  // A loop correction moved the world: the next state's distance is measured from the corrected last position.
  void moveWorld(const Eigen::Isometry3d& T_new_old);
  // [m] the path length between t0 and t1 (t0 <= t1), linear between the states; the part outside the states kept
  // (before the oldest, after the newest) counts as no motion.
  double between(Time t0, Time t1) const;
  Time newest() const { return s_.empty() ? Time{0} : s_.back().first; }

  static constexpr Time kKept = 120'000'000'000;  // [ns] (at 10 Hz sweeps: 1200 entries)

 private:
  double at(Time t) const;  // the path length at t, clamped to the states kept
  std::deque<std::pair<Time, double>> s_;  // (t [ns], path length since the first state [m])
  std::optional<Eigen::Vector3d> last_;
};

}  // namespace drover::pipeline
