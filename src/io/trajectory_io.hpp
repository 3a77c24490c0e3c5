#pragma once
// Trajectory files: TUM, KITTI and EuRoC ground-truth CSV, read and written.
#include <cstdio>
#include <optional>
#include <string>

#include "types/trajectory.hpp"

namespace drover::io {

enum class TrajectoryFormat { kTum, kKitti, kEuroc };

// "tum" | "kitti" | "euroc"; throws std::invalid_argument otherwise.
TrajectoryFormat parseTrajectoryFormat(const std::string& name);

// TUM: one pose a line, "t x y z qx qy qz qw", t in seconds; '#' lines and blank lines skipped.
Trajectory readTum(const std::string& path);
// KITTI: 12 numbers a line, row-major 3x4 [R | t]. Times from `times_path` (one value in seconds a line, as
// KITTI's times.txt) when given, otherwise t = line index * 1 s, i.e. poses are matched by index.
Trajectory readKitti(const std::string& path, const std::optional<std::string>& times_path = std::nullopt);
// EuRoC state_groundtruth_estimate0/data.csv: "t_ns, px, py, pz, qw, qx, qy, qz, ..." (extra columns ignored).
Trajectory readEurocCsv(const std::string& path);
Trajectory readTrajectory(const std::string& path, TrajectoryFormat format,
                          const std::optional<std::string>& times_path = std::nullopt);

// Writers replace the file atomically (write to a temporary beside it, then rename), so an interrupted run
// never leaves a half-written trajectory. Quaternions are normalised on write.
void writeTum(const std::string& path, const Trajectory& trajectory);
void writeKitti(const std::string& path, const Trajectory& trajectory,
                const std::optional<std::string>& times_path = std::nullopt);
void writeEurocCsv(const std::string& path, const Trajectory& trajectory);
void writeTrajectory(const std::string& path, TrajectoryFormat format, const Trajectory& trajectory);

// A TUM file written pose by pose, for trajectories too long to hold (the IMU-rate odometry of an hour-long run).
// Not atomic itself: write it inside a staged folder (io::StagedFolder). Refuses what writeTum refuses (a
// non-finite pose, one not after the previous); throws IoError when the file cannot be opened or written.
class TumStream {
 public:
  explicit TumStream(std::string path);
  ~TumStream();  // closes without checking: call close() to learn of a failed write
  TumStream(const TumStream&) = delete;
  TumStream& operator=(const TumStream&) = delete;
  void add(const StampedPose& pose);
  void flush();  // throws IoError when a write failed
  void close();  // flushes; idempotent
  std::size_t size() const { return count_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::size_t count_ = 0;
  Time last_ = 0;
};

// The unit quaternion of R with w >= 0: q and -q are the same rotation, and writing one of them makes files
// deterministic and diffable.
Eigen::Quaterniond canonicalQuaternion(const Eigen::Matrix3d& R);

// Writes `content` to `path` atomically (temporary file + rename). Throws IoError on failure.
void writeFileAtomically(const std::string& path, const std::string& content);

}  // namespace drover::io
