#pragma once
// A pose at each of a list of times from a trajectory that may lack some of them: a file whose promise is one line
// per scan (KITTI's poses.txt, matched by line, not by time) needs a pose even for a sweep the odometry skipped.
#include <vector>

#include "types/trajectory.hpp"

namespace drover::geometry {

enum class FillKind {
  kEstimated,     // the trajectory has a pose at exactly this time
  kInterpolated,  // between the two estimated poses around it (geodesic on SE(3))
  kExtrapolated,  // before the first or after the last estimate: constant velocity of the nearest two (or held)
};
const char* toString(FillKind kind);

struct FilledPose {
  StampedPose pose;
  FillKind kind = FillKind::kEstimated;
};

// One pose per entry of `times` [ns]. `trajectory` must be non-empty and time-ordered (std::invalid_argument
// otherwise). Extrapolation uses the screw motion of the nearest two poses, so a vehicle driving on keeps driving.
std::vector<FilledPose> posesAtTimes(const Trajectory& trajectory, const std::vector<Time>& times);

}  // namespace drover::geometry
