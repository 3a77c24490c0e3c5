#pragma once
// Vision-only structure from motion over the initialisation window (Qin, Li, Shen, "VINS-Mono", T-RO 2018,
// Sec. V-A; its solve_5pts.cpp and initial_sfm.cpp):
//   1. frame l: the oldest frame with enough correspondences and average parallax to the LAST frame; their
//      relative pose from the essential matrix (five-point RANSAC + cheirality), translation of unit length;
//   2. triangulate l <-> last, PnP the frames outward from l, triangulate more, PnP the frames before l;
//   3. bundle adjustment of every camera pose and point (Ceres), gauge: frame l's pose and the last frame's
//      position held fixed.
// Poses and points are up to one unknown scale, in the frame of camera l ("c_l"). Coordinates are undistorted
// normalised image coordinates (x/z, y/z); pixel thresholds are converted with a virtual focal length.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace drover::vio {

// Feature id -> undistorted normalised coordinates (x/z, y/z) of its observation in one frame.
using FrameFeatures = std::map<std::uint64_t, Eigen::Vector2d>;

struct SfmConfig {
  double focal_px = 460;            // virtual focal length for pixel thresholds (VINS-Mono FOCAL_LENGTH)
  double min_parallax_px = 30;      // average raw parallax l <-> last must exceed this (VINS-Mono: 30 px)
  // Average parallax l <-> last left after removing the best pure rotation between them (a rotation-only fit
  // of the bearings). VINS-Mono has no such test; without it a rotation-only window (large raw parallax, no
  // baseline) passes the essential matrix with an arbitrary translation.
  double min_translation_parallax_px = 5;
  int min_correspondences = 20;     // features seen in both l and the last frame, more than this (VINS-Mono: 20)
  int min_essential_inliers = 12;   // five-point RANSAC inliers, more than this (VINS-Mono: 12)
  double ransac_threshold_px = 0.3; // essential-matrix RANSAC threshold (VINS-Mono: 0.3 / 460 normalised)
  int min_pnp_points = 10;          // triangulated points a frame must see for PnP (VINS-Mono: 10)
  double max_reprojection_px = 3;   // mean bundle-adjustment reprojection error after convergence [px]
  // Empty when valid.
  std::string validate() const;
};

struct SfmResult {
  bool ok = false;
  std::string why;  // one line naming the failed step and the measured value vs the threshold
  int l = -1;       // index of the reference frame
  // Pose of camera k in the frame of camera l, translation up to scale (|p_l_last| = 1 before the adjustment).
  std::vector<Eigen::Isometry3d> T_l_cam;
  std::map<std::uint64_t, Eigen::Vector3d> points_l;  // triangulated features in c_l, same scale
  double raw_parallax_px = 0;          // average parallax l <-> last
  double translation_parallax_px = 0;  // same after the best rotation-only fit
  double reprojection_px = 0;          // mean reprojection error after the adjustment [px]
};

// Relative pose of two views from normalised correspondences (VINS-Mono solveRelativeRT): the pose of view b in
// view a, T_a_b, with |t| = 1. Returns false (and sets why) with too few correspondences or inliers.
bool relativePose(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                  const SfmConfig& config, Eigen::Isometry3d& T_a_b, std::string& why);

// Mean parallax [px] between matched normalised points a[i] <-> b[i], raw and after the least-squares rotation
// R (Kabsch on unit bearings, b ~ R a) is removed.
double meanParallaxPx(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b, double focal_px);
double rotationCompensatedParallaxPx(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                                     double focal_px);

// Linear (DLT) triangulation of one point from two camera poses T_cam_world; returns false when the point is
// behind either camera or the system is degenerate.
bool triangulatePoint(const Eigen::Isometry3d& T_c0_w, const Eigen::Isometry3d& T_c1_w, const Eigen::Vector2d& x0,
                      const Eigen::Vector2d& x1, Eigen::Vector3d& p_w);

// The whole SfM of the window. Throws std::invalid_argument when config.validate() fails.
SfmResult globalSfm(const std::vector<FrameFeatures>& frames, const SfmConfig& config);

}  // namespace drover::vio
