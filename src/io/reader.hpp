#pragma once
#include <memory>
#include <optional>
#include <string>

#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "types/trajectory.hpp"

namespace drover::io {

// Ground truth of a dataset with the frame its poses describe, e.g. "lidar", "cam0", "imu".
struct GroundTruth {
  Trajectory poses;        // T_world_body, time-ordered
  std::string body_frame;  // empty poses => the dataset has no ground truth
};

// A dataset as one time-ordered stream of measurements. Readers index times up front and load the heavy
// payloads (scans, images) lazily in next(), so memory stays flat on long sequences.
// Every reader throws IoError (naming file and record) on bad input; it never returns silently wrong data.
class Reader {
 public:
  virtual ~Reader() = default;
  // Next measurement in non-decreasing time order; std::nullopt at the end.
  virtual std::optional<Measurement> next() = 0;
  virtual const Calibration& calibration() const = 0;
  virtual const GroundTruth& groundTruth() const = 0;
  // Human-readable description ("KITTI odometry 00", "bag foo.bag") for logs.
  virtual std::string describe() const = 0;
};

}  // namespace drover::io
