#pragma once
#include <Eigen/Geometry>
#include <vector>

#include "types/time.hpp"

namespace drover {

// T_world_body at time t. Which body (lidar, camera 0, IMU) is stated where the trajectory is produced.
struct StampedPose {
  Time t = 0;  // [ns]
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
};

using Trajectory = std::vector<StampedPose>;

}  // namespace drover
