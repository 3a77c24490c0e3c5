#pragma once
// What a run keeps of its sweeps while it runs, bounded for hour-long runs: counts, per-stage timing statistics and
// the per-sweep diagnostic lines (sweeps.jsonl), streamed to the run folder or, live, the newest few kept.
#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "io/trajectory_io.hpp"
#include "pipeline/lidar_odometry.hpp"

namespace drover::cli {

// p50 / p95 / max / mean of a stream of non-negative values in bounded memory: exact while there are at most
// kExact values, then from a histogram with bins 1 % wide (log-spaced from 1e-4 to 1e7; outside, the ends).
class BoundedQuantiles {
 public:
  static constexpr std::size_t kExact = 20'000;
  void add(double v);
  std::size_t count() const { return count_; }
  double mean() const { return count_ ? sum_ / static_cast<double>(count_) : 0.0; }
  double max() const { return max_; }
  double quantile(double q) const;  // q in [0, 1]; the value of rank round(q (n - 1)); 0 when empty
  // {"p50", "p95", "max", "count"}, nulls when empty (--realtime's latency_ms).
  nlohmann::json percentiles() const;

 private:
  static std::size_t bin(double v);
  static double binValue(std::size_t b);
  std::vector<double> exact_;
  std::vector<std::uint32_t> bins_;  // once count_ > kExact
  std::size_t count_ = 0;
  double sum_ = 0, max_ = 0;
};

// One JSON object a line (JSONL): a run's per-sweep and per-frame records in bounded memory, streamed to the run
// folder as they come or, live, the newest few kept.
class JsonLines {
 public:
  // record: what a line is ("sweep"), for the error of a failed write.
  explicit JsonLines(std::string record) : record_(std::move(record)) {}
  // Each line written to `path` as it comes (drover run: OUT.partial/sweeps.jsonl). Throws IoError.
  void streamTo(const std::string& path);
  // Only the newest `n` lines kept in memory (the ROS node, whose save may come at any time).
  void keepNewest(std::size_t n);
  void add(const nlohmann::json& line);  // throws IoError on a failed write
  // The streamed file closed (flushed; throws IoError on a failed write), or the kept lines written to `path`.
  void finish(const std::string& path);
  std::size_t lines() const { return lines_; }
  bool streaming() const { return file_ != nullptr; }

 private:
  std::string record_;
  std::shared_ptr<std::FILE> file_;
  std::string path_;
  std::deque<std::string> newest_;
  std::size_t keep_ = 0, lines_ = 0;
};

// report.json's per-sweep lines (sweeps.jsonl: t, status, iterations, fitness_m, inliers, points, features, keyframe,
// degenerate, min_eigenvalue, imu, reset, total_ms; degenerate_directions on a degenerate sweep, warning on a sweep
// with one, and with the IMU v_world / gyro_bias / acc_bias).
class SweepLog : public JsonLines {
 public:
  SweepLog() : JsonLines("sweep") {}
  void add(const pipeline::ScanOutcome& s) { JsonLines::add(line(s)); }
  static nlohmann::json line(const pipeline::ScanOutcome& s);
};

// The IMU-rate odometry streamed to a TUM file as it comes (an hour at 200 Hz would be ~100 MB in memory), in
// trajectory.tum's body frame. Thread-safe: the live system publishes from the pushing thread while a save copies.
class ImuRateFile {
 public:
  // T_imu_body: identity when trajectory.tum's body is the IMU, T_imu_lidar when it is the lidar. Throws IoError.
  ImuRateFile(const std::string& path, const Eigen::Isometry3d& T_imu_body);
  void add(Time t, const Eigen::Isometry3d& T_world_imu);  // a pose not after the previous one is skipped
  struct Summary {
    std::size_t poses = 0;
    Time first = 0, last = 0;  // [ns]
  };
  // Flushes and, when `dest` is another file, copies the poses so far there. Throws IoError.
  Summary copyTo(const std::string& dest);

 private:
  std::mutex mutex_;
  io::TumStream stream_;
  Eigen::Isometry3d T_imu_body_;
  Summary summary_;
};

struct RunRecord {
  // The processed sweeps: how many, the first and last stamps [ns], per-stage timings [ms], the per-sweep lines.
  std::size_t sweeps = 0;
  Time first_t = 0, last_t = 0;
  std::array<BoundedQuantiles, 8> stage_ms;  // preprocess, deskew, features, map, match, smoother, loop, total
  SweepLog log;
  std::shared_ptr<ImuRateFile> imu_rate;  // with the IMU: trajectory_imu_rate.tum, streamed
  std::vector<Time> scan_times;  // [ns] every sweep handed to the odometry, on the IMU clock (KITTI's one line per scan)
  double wall_s = 0;  // [s] wall time of the odometry loop (reading included)
  double data_s = 0;  // [s] time spanned by the processed sweeps
  std::size_t notices_shown = 0;  // OdometryStats::notices already printed
  bool fusion_announced = false;  // the "fusing: ..." line was printed
  std::size_t reader_notices_shown = 0;  // io::ReaderDrops::notices already printed
  std::size_t measurements_dropped = 0;  // by the reader: a repeated or backwards stamp, or an unusable reading
  // Why the run stopped (report.json "end"): "end of data", "--duration reached", "--max-frames reached" or
  // "interrupted by SIGINT" / "SIGTERM".
  std::string end = "end of data";

  void add(const pipeline::ScanOutcome& s);  // counts, timings, the log line
  static const std::array<const char*, 8>& stageNames();
};

}  // namespace drover::cli
