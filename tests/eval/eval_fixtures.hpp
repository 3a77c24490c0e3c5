#pragma once
// Constructed trajectories for the eval tests: a wiggly 3D reference whose positions are not collinear.
#include <Eigen/Geometry>
#include <cmath>

#include "geometry/so3.hpp"
#include "types/trajectory.hpp"

namespace drover::eval::test {

inline Eigen::Isometry3d pose(const Eigen::Vector3d& rotvec, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = geometry::expSO3(rotvec);
  T.translation() = t;
  return T;
}

// Pose i of the reference: a loop in x-y with height changes and turning orientation, 0.1 s apart.
inline StampedPose referencePose(int i) {
  const double a = 0.3 * i;
  const Eigen::Vector3d p(10.0 * std::cos(a) + 0.5 * i, 6.0 * std::sin(a), 1.0 + std::sin(0.7 * i));
  return {static_cast<Time>(i) * 100'000'000, pose(Eigen::Vector3d(0.1 * std::sin(a), 0.05 * i, a), p)};
}

inline Trajectory referenceTrajectory(int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) t.push_back(referencePose(i));
  return t;
}

}  // namespace drover::eval::test
