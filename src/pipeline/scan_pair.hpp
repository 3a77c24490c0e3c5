#pragma once
// Loop closure on two single scans (`drover loop pair`): are they the same place, at which relative yaw, and what
// does scan matching make of it? Each scan is prepared as the odometry prepares a sweep (sanitize, ring/time
// inference when the lidar gives none, LOAM features; no deskew: KITTI's scans are already motion-compensated),
// A is the database side and B the query (laterally augmented, as in LoopClosure), and B's features are registered
// to A's from the Scan Context guess by the loop verifier.
#include <string>

#include "loop/loop_verifier.hpp"
#include "loop/scan_context.hpp"
#include "pipeline/odometry_config.hpp"
#include "types/lidar.hpp"

namespace drover::pipeline {

struct ScanPairResult {
  loop::ShiftMatch plain;      // full shift search of the real positions (no augmentation)
  loop::AugmentedMatch match;  // the decision: full search against B's virtual positions
  bool same_place = false;     // match.match.distance < the descriptor threshold
  // B registered to A (T_candidate_query = T_A_B), tried whether or not same_place holds.
  loop::LoopVerification icp;
  Eigen::Isometry3d T_A_B_guess = Eigen::Isometry3d::Identity();  // the Scan Context guess it started from
  std::size_t points_a = 0, points_b = 0;                         // valid points after sanitising
};

// One scan prepared as the odometry prepares a sweep (no deskew): sanitized in place, ring/time inferred when absent,
// LOAM features extracted. Throws std::invalid_argument naming the scan (`name`) when fewer than config.min_points
// valid points remain.
lidar::FeatureSet prepareScan(LidarScan& scan, const OdometryConfig& config, const std::string& name = "scan");

// Uses config.layout, config.features, config.loop.database.descriptor and config.loop.verifier. Throws
// std::invalid_argument naming the scan (name_a, name_b: e.g. its file) when it has fewer than config.min_points
// valid points.
ScanPairResult compareScans(LidarScan a, LidarScan b, const OdometryConfig& config,
                            const std::string& name_a = "scan A", const std::string& name_b = "scan B");

}  // namespace drover::pipeline
