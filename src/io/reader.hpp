#pragma once
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "types/trajectory.hpp"

namespace drover::io {

// Ground truth of a dataset with the frame its poses describe, e.g. "lidar", "cam0", "imu".
struct GroundTruth {
  Trajectory poses;        // T_world_body, time-ordered
  std::string body_frame;  // empty poses => the dataset has no ground truth
};

// Measurements a reader dropped instead of failing: real sensors and drivers repeat or reorder a stamp now and then
// (non-finite lidar points are dropped per scan and counted in LidarScan::dropped_nonfinite).
struct ReaderDrops {
  // Stamp not after the previous one of the same sensor (duplicate or backwards), or an unusable reading (a bag's
  // IMU message with a NaN rate or acceleration).
  std::size_t measurements = 0;
  static constexpr std::size_t kMaxNotices = 200;
  std::vector<std::string> notices;  // "FILE (RECORD): what was dropped and why", the first kMaxNotices
};

// A dataset as one time-ordered stream of measurements. Readers index times up front and load the heavy
// payloads (scans, images) lazily in next(), so memory stays flat on long sequences.
// Every reader throws IoError (naming file and record) on structurally bad input (unreadable, truncated, unparsable
// files); it never returns silently wrong data. A measurement whose stamp does not advance on its sensor is dropped
// and counted in drops() (a warning for the caller to print), and non-finite lidar points are dropped from their scan.
class Reader {
 public:
  virtual ~Reader() = default;
  // Next measurement in non-decreasing time order; std::nullopt at the end.
  virtual std::optional<Measurement> next() = 0;
  virtual const Calibration& calibration() const = 0;
  virtual const GroundTruth& groundTruth() const = 0;
  // Human-readable description ("KITTI odometry 00", "bag foo.bag") for logs.
  virtual std::string describe() const = 0;
  // What was dropped so far; grows as next() goes.
  const ReaderDrops& drops() const { return drops_; }

 protected:
  // Counts a dropped measurement; `notice` names the file and record.
  void dropMeasurement(std::string notice) {
    ++drops_.measurements;
    if (drops_.notices.size() < ReaderDrops::kMaxNotices) drops_.notices.push_back(std::move(notice));
  }

 private:
  ReaderDrops drops_;
};

}  // namespace drover::io
