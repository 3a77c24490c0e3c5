#pragma once
// LOAM edge and plane features of one deskewed sweep (Zhang & Singh, "LOAM", RSS 2014, Sec. V-A; as implemented
// in LIO-SAM's featureExtraction.cpp), with its known limits removed:
//  - each ring keeps its points in firing order instead of projecting them into a fixed range image, so none is lost
//    to a cell collision (KITTI rings hold up to ~2160 points for 2083 nominal columns);
//  - smoothness, occlusion and beam-parallel tests run per ring, never across the end of one ring and the start of
//    the next;
//  - flat points are the points with curvature < surf_threshold (LIO-SAM keeps every non-edge point, occluded
//    ones included), then voxel-downsampled; every sub-region's last point is used.
// Curvature (LIO-SAM calculateSmoothness, the unnormalised form of LOAM Eq. 1):
//   c_i = (sum_{j = i-5..i+5, j != i} (r_j - r_i))^2  [m^2], r = range.
#include <cstddef>
#include <string>

#include "lidar/feature_set.hpp"
#include "types/lidar.hpp"

namespace drover::lidar {

struct FeatureExtractorConfig {
  int columns = 1800;                 // firings per revolution (LIO-SAM Horizon_SCAN): the angular resolution that
                                      // turns an azimuth gap into a column gap
  double min_range = 1.0;             // [m] closer points are ignored (LIO-SAM lidarMinRange)
  double max_range = 100.0;           // [m] farther points are ignored (LIO-SAM lidarMaxRange)
  int half_window = 5;                // neighbours on each side in the curvature sum (LIO-SAM: 5)
  float edge_threshold = 1.0f;        // [m^2] curvature above which a point may be an edge (edgeThreshold)
  float surf_threshold = 0.1f;        // [m^2] curvature below which a point is flat (surfThreshold)
  int sub_regions = 6;                // equal parts of each ring, edges picked per part (LIO-SAM: 6)
  int max_edges_per_region = 20;      // sharpest points kept per part (LIO-SAM: 20)
  int suppression_radius = 5;         // neighbours on each side barred after an edge is picked (LIO-SAM: 5)
  int max_column_gap = 10;            // [columns] neighbours farther apart are not neighbours (LIO-SAM: 10)
  float occlusion_depth_gap = 0.3f;   // [m] range step between neighbours that marks an occlusion (LIO-SAM: 0.3)
  float parallel_ratio = 0.02f;       // a point whose range differs from both neighbours by more than this
                                      // fraction of its range lies on a surface parallel to the beam (LIO-SAM: 0.02)
  float edge_leaf = 0.0f;             // [m] voxel leaf for edges; 0 keeps them all (LIO-SAM downsamples corners at
                                      // mappingCornerLeafSize 0.2 only in the mapper)
  float surf_leaf = 0.4f;             // [m] voxel leaf for flat points (odometrySurfLeafSize); 0 keeps them all
  float full_leaf = 0.4f;             // [m] voxel leaf for the full cloud; 0 keeps every valid point
  // Within a ring, points are taken in their stored order (the firing order of every Velodyne/Ouster driver, the
  // simulator and KITTI's .bin). true: sort each ring by time offset instead, for sources that store points out of
  // firing order (needs measured times: times inferred from azimuth would reorder KITTI's parallax jitter).
  bool sort_by_time = false;
  std::string validate() const;       // empty when valid
};

enum class ExtractionStatus {
  kOk,
  kEmpty,        // no valid point
  kTooFewPoints, // valid points, but no ring long enough for the curvature window: no edges or planes
};

struct ExtractionStats {
  std::size_t input_points = 0;
  std::size_t non_finite = 0;        // dropped: NaN or inf coordinate
  std::size_t out_of_range = 0;      // dropped: range outside [min_range, max_range]
  std::size_t valid_points = 0;
  std::size_t rejected = 0;          // occluded or beam-parallel points (never features)
  std::size_t edges_raw = 0;         // edges / flat points before downsampling
  std::size_t planes_raw = 0;
};

struct Extraction {
  ExtractionStatus status = ExtractionStatus::kOk;
  FeatureSet features;               // t = scan.t; points in the lidar frame at the sweep start
  ExtractionStats stats;
};

class FeatureExtractor {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit FeatureExtractor(const FeatureExtractorConfig& config = {});

  // `deskewed`: a sweep already moved into the lidar frame at its start. Requires rings (scan.has_ring: measured,
  // or set by inferRings()); throws std::invalid_argument otherwise. Each ring's points are taken in stored order
  // (or by time offset, see sort_by_time).
  Extraction extract(const LidarScan& deskewed) const;

  const FeatureExtractorConfig& config() const { return config_; }

 private:
  FeatureExtractorConfig config_;
};

}  // namespace drover::lidar
