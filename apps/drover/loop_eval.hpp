#pragma once
// The data side of `drover loop eval` (cmd_loop_eval.cpp parses and prints): mode A streams a dataset, keeps a
// keyframe every keyframe_distance metres of ground-truth travel and queries a Scan Context database with each
// (loop_eval_course.cpp); mode B scores a list of labelled KITTI scan pairs (loop_eval_pairs.cpp). The maths of the
// counts is in loop/place_recognition_eval.hpp.
#include <cstddef>
#include <string>
#include <vector>

#include "lidar/feature_set.hpp"
#include "loop/place_recognition_eval.hpp"
#include "pipeline/odometry_config.hpp"
#include "types/lidar.hpp"

namespace drover::cli {

struct LoopEvalOptions {
  std::string dataset, format = "sim", config, pairs, json;
  double keyframe_distance = 1.0;  // [m] of ground-truth travel between keyframes
  double true_distance = 3.0;      // [m] a true revisit; the right place is within twice this
  double threshold = -1;           // [-] < 0: the config's loop.scan_context.threshold
  bool no_augment = false;         // no lateral augmentation of the queries
  std::size_t max_frames = 0;      // [scans] read at most this many (0 = all)
  bool quiet = false;
};

struct LoopEvalData {
  std::vector<loop::PlaceQuery> queries;
  std::size_t scans = 0, keyframes = 0, skipped = 0;  // scans read, keyframes made, keyframes skipped (few points)
  // Detected right-place queries (TP at the threshold) whose prior-narrowed shift (prior: the ground-truth relative
  // yaw, +-search_radius) was computed, and how many of those equal the full search's shift.
  std::size_t narrowed_checked = 0, narrowed_equal = 0;
  double descriptor_ms = 0, query_ms = 0;  // [ms] mean per keyframe / per query (mode B: per pair, no query)
  struct Detection {
    Time t_query = 0, t_candidate = 0;  // [ns]
    double distance = 0;                // [-] Scan Context
    double true_distance = 0;           // [m] between the two by the ground truth
  };
  std::vector<Detection> false_positives;  // mode A: detections at the threshold of the wrong place
};

// The platform config (without --config: the KITTI HDL-64E as config/kitti.yaml describes it), with the
// descriptor's threshold and augmentation set from the options.
pipeline::OdometryConfig loopEvalConfig(const LoopEvalOptions& o);

// The cloud the descriptor is made of, as drover run makes it: sanitize, times and rings inferred when the scan has
// none, the feature extractor's (voxel-downsampled) full cloud. Throws std::invalid_argument naming the scan (`name`)
// when it has fewer than config.min_points valid points.
lidar::PointCloud descriptorCloud(LidarScan scan, const pipeline::OdometryConfig& config,
                                  const std::string& name = "scan");

LoopEvalData evaluateCourse(const LoopEvalOptions& o, const pipeline::OdometryConfig& config);
LoopEvalData evaluatePairs(const LoopEvalOptions& o, const pipeline::OdometryConfig& config);

}  // namespace drover::cli
