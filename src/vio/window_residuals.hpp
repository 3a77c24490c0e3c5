#pragma once
// The residual blocks of the window (vio-internal): built once per solve, owned here so that the same cost
// objects serve the solve and the marginalisation after it.
#include <ceres/cost_function.h>
#include <ceres/loss_function.h>

#include <memory>
#include <set>
#include <vector>

#include "vio/sliding_window.hpp"

namespace drover::vio {

struct SlidingWindowEstimator::Residuals {
  struct Item {
    std::unique_ptr<ceres::CostFunction> cost;
    const ceres::LossFunction* loss = nullptr;
    std::vector<double*> blocks;
  };
  std::vector<Item> items;
  std::unique_ptr<ceres::LossFunction> robust;
  std::unique_ptr<ceres::LossFunction> ground_robust;  // Cauchy at one sigma of the ground height
  // Every feature block used, in the order of the features (by id). The marginalisation declares its blocks in this
  // order, so it must not follow their addresses: a std::set<double*> made the replay with a lidar run-to-run
  // different (the LIS's worker threads move the heap, the declaration order changed the sums in the last bits).
  std::vector<double*> inverse_depths;
  std::set<const double*> fixed_depths;  // depth_mode fixed: lidar-anchored features (membership only)
  int features = 0, with_lidar_depth = 0, seen_three_times = 0;  // features used; lidar-anchored; >= 3 frames
  int on_ground = 0;                                             // features held to the ground (ground_height_m)
};

}  // namespace drover::vio
