#pragma once
// KITTI odometry segment drift, as evaluate_odometry.cpp of the KITTI odometry devkit (Geiger et al. 2012):
// for every step_size-th frame as start and every segment length L, the last frame is the first one whose
// ground-truth path distance from the start exceeds L (strictly); the segment error is
//   E = (P_first^-1 P_last)^-1 (G_first^-1 G_last),  r_err = acos(clamp((tr R(E) - 1) / 2)) / L,  t_err = |t(E)| / L
// and t_err%, r_err deg/100 m average over all segments of all lengths. Poses are matched by index.
// The devkit computes in float; this computes in double.
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace drover::eval {

struct KittiDriftOptions {
  std::vector<double> lengths{100, 200, 300, 400, 500, 600, 700, 800};  // [m] segment lengths
  std::size_t step_size = 10;                                           // [frames] between segment starts
};

struct KittiSegmentError {
  std::size_t first_frame = 0;
  std::size_t last_frame = 0;
  double length = 0.0;  // [m] nominal segment length L
  double r_err = 0.0;   // [rad/m]
  double t_err = 0.0;   // [m/m]
};

struct KittiLengthDrift {
  double length = 0.0;  // [m]
  std::size_t segments = 0;
  double t_err_percent = 0.0;       // 100 * mean t_err over this length's segments (0 when none)
  double r_err_deg_per_100m = 0.0;  // mean r_err * 180/pi * 100
};

struct KittiDriftResult {
  double t_err_percent = 0.0;       // 100 * mean t_err over all segments
  double r_err_deg_per_100m = 0.0;  // mean r_err [rad/m] * 180/pi * 100
  std::vector<KittiSegmentError> segments;
  std::vector<KittiLengthDrift> per_length;  // one entry per options.lengths, in that order
  double path_length = 0.0;                  // [m] of the ground truth
};

// gt and est: T_world_cam per frame. Throws std::invalid_argument when the counts differ, a list is empty,
// the options are invalid, or no segment fits (ground truth shorter than the shortest length).
KittiDriftResult computeKittiDrift(const std::vector<Eigen::Isometry3d>& gt, const std::vector<Eigen::Isometry3d>& est,
                                   const KittiDriftOptions& options = {});

// Devkit helpers, exposed for tests: cumulative path distances, and the first frame whose distance from
// first_frame exceeds len (-1 when none).
std::vector<double> trajectoryDistances(const std::vector<Eigen::Isometry3d>& poses);
long lastFrameFromSegmentLength(const std::vector<double>& dist, std::size_t first_frame, double len);

}  // namespace drover::eval
