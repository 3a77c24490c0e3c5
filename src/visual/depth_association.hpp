#pragma once
// Lidar depth for visual features, LVI-SAM's method (Shan et al., "LVI-SAM", ICRA 2021, Sec. III-B.2, Fig. 3;
// visual_feature/feature_tracker_node's depth registration): keep the deskewed sweeps of a recent time window in the
// world frame (voxel-downsampled), move them into the current camera frame, keep the nearest point per cell of a
// spherical (azimuth x elevation) grid, put those on the unit sphere, and for each feature ray take the three nearest
// lidar points on the sphere and intersect the ray with their plane. (Departure: when the third nearest is collinear
// with the first two, as often on one scan line, the next non-collinear neighbour among the 8 nearest within the
// angular limit replaces it; LVI-SAM would take the ill-conditioned plane.) The depth is rejected when the three
// points' ranges spread more than `max_depth_spread` (a depth discontinuity: the plane would bridge foreground and
// background), when they are not all close to the ray on the sphere, when the ray grazes their plane, or when the depth
// falls outside [min_depth, max_depth]. LVI-SAM clamps the intersection to the three ranges; that is wrong on a plane
// seen head-on (the ray's range is below all three), so here the intersection is kept as it is and rejected (as
// grazing) only when it lies more than max_depth_spread outside the three ranges.
//
// Frames: points in the world frame [m]; the camera pose is T_world_cam (z forward, x right, y down). The depth
// returned is along the optical axis (z), so the feature's point is depth * (x_n, y_n, 1).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <deque>
#include <string>
#include <vector>

#include "types/time.hpp"

namespace drover::visual {

struct DepthAssociationConfig {
  double window_s = 5.0;            // [s] sweeps kept (LVI-SAM: 5 s of registered clouds)
  double voxel_size = 0.2;          // [m] voxel downsampling of each sweep (LVI-SAM: 0.2); 0 = none
  double grid_resolution_deg = 0.5;  // [deg] spherical grid cell (LVI-SAM: 180 / 360 bins)
  double neighbour_cells = 5;       // the 3 neighbours must lie within this many cells of the ray (LVI-SAM: 5)
  double max_depth_spread = 2.0;    // [m] largest range difference of the 3 neighbours (LVI-SAM: 2)
  double min_depth = 0.5;           // [m] along the optical axis (LVI-SAM keeps depths > 3 m for its outdoor rigs)
  double max_depth = 100.0;         // [m]
  double min_incidence_cos = 0.05;  // |cos| of the ray to the plane normal below which the ray grazes the plane
                                    // (also: no non-collinear neighbour triangle -> kGrazing)
  std::string validate() const;     // empty = valid, else names the bad value
};

enum class DepthStatus { kOk, kNoNeighbours, kDiscontinuity, kGrazing, kOutOfRange };

struct FeatureDepth {
  DepthStatus status = DepthStatus::kNoNeighbours;
  double depth = 0;   // [m] along the camera's z axis; valid when status == kOk
  double spread = 0;  // [m] range spread of the three lidar neighbours (the VIS's depth sigma grows with it)
};

struct DepthAssociationResult {
  std::vector<FeatureDepth> features;  // one per input feature, same order
  int associated = 0;                  // status kOk
  int rejected_discontinuity = 0, rejected_range = 0, rejected_grazing = 0, no_neighbours = 0;
  std::size_t points_used = 0;         // lidar points on the sphere after the grid
};

class DepthAssociator {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit DepthAssociator(const DepthAssociationConfig& config);

  // Adds a deskewed sweep stamped t [ns], points in the world frame [m]. Drops sweeps older than t - window.
  // Throws std::invalid_argument when t goes back in time.
  void addSweep(Time t, const std::vector<Eigen::Vector3d>& points_world);
  // Depth of each feature (undistorted normalised coordinates) in the camera at pose T_world_cam, time t [ns]
  // (sweeps newer than t are not used, older than t - window are ignored).
  DepthAssociationResult associate(Time t, const Eigen::Isometry3d& T_world_cam,
                                   const std::vector<Eigen::Vector2d>& normalized) const;
  // The world frame moved (a loop correction of the LIS): the stored sweeps' points become T_new_old * p, so that
  // they agree with the camera poses the corrected LIS gives from now on.
  void reanchor(const Eigen::Isometry3d& T_new_old);
  std::size_t sweepCount() const { return sweeps_.size(); }
  const DepthAssociationConfig& config() const { return config_; }

 private:
  struct Sweep {
    Time t;
    std::vector<Eigen::Vector3d> points_world;  // double: the plane of three close points needs it
  };
  DepthAssociationConfig config_;
  std::deque<Sweep> sweeps_;
};

}  // namespace drover::visual
