#pragma once
// The VIS's attitude over the run, for loop closure's shift search (LVI-SAM, Shan et al. ICRA 2021, Sec. III-D:
// the search narrowed to A +- dh around the VIS's relative yaw between the candidate and the query). The VIS is an
// odometry: between two keyframe times far apart its relative rotation is only trusted when it tracked through
// both without a reset (the same reset ID), and a state is taken only when one lies within max_gap of each time.
// Thread-safe: the live system adds from the VIS thread and asks from the loop thread.
#include <Eigen/Geometry>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "pipeline/loop_closure.hpp"
#include "pipeline/visual_motion.hpp"

namespace drover::pipeline {

class VisualYawHistory {
 public:
  // T_imu_lidar: the lidar's mount (the prior is the lidars' relative yaw). Keeps one state per `spacing` [s].
  explicit VisualYawHistory(const Eigen::Isometry3d& T_imu_lidar, double spacing_s = 0.1, double max_gap_s = 0.15);

  void add(const VisualState& state);  // in time order; older or too close to the previous kept one: ignored
  // The yaw of the query's lidar in the candidate's, p_candidate = Rz(yaw) p_query (pipeline::VisualYawPrior), from
  // the VIS states nearest the two times; nothing when either has none within max_gap or they differ in reset ID.
  std::optional<double> yaw(Time t_candidate, Time t_query) const;
  // As a loop closure prior; the history must outlive it.
  VisualYawPrior prior() const;
  std::size_t size() const;

 private:
  struct Entry {
    Time t;
    Eigen::Quaterniond q_world_imu;
    std::uint32_t reset_id;
  };
  const Entry* nearest(Time t) const;

  Eigen::Quaterniond q_imu_lidar_;
  Time spacing_, max_gap_;
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;  // 10 per second: 48 bytes each, 1.7 MB an hour
};

}  // namespace drover::pipeline
