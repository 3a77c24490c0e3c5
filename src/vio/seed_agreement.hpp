#pragma once
// How well a seeded window's motion explains its tracks: the LIS's poses move the window, the lidar gives the
// anchors' depths, and a track that does not follow that motion reprojects off its observations. Tracks that slide
// along edges on a textureless surface, or a seed whose velocity has drifted (the IMU carrying a lidar-degenerate
// corridor), both show up as a large median reprojection error, where a sound seed on sound tracks gives ~1 px.
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

#include "vio/feature_manager.hpp"

namespace drover::vio {

struct SeedAgreement {
  std::size_t observations = 0;  // non-anchor observations of lidar-anchored features
  double median_px = 0;          // [px at focal_px] their median reprojection error
};

// T_world_cam per window frame (index as the features' observations); only features whose depth came from the
// lidar count (a triangulated depth fits the poses it was triangulated with, whatever they are).
SeedAgreement seedAgreement(const FeatureManager& features, const std::vector<Eigen::Isometry3d>& T_world_cam,
                            double focal_px);

}  // namespace drover::vio
