#pragma once
// The `visual:` section of a platform config (config/*.yaml) -> the visual front end's configs. Every key is
// optional (left out = the default in the component's Config, whose header gives its unit); an unknown key or a
// bad value is an IoError naming the file, the line and the dotted key. Sections and keys so far:
//   visual:
//     detector:       type (superpoint | shi-tomasi | orb)
//       shi_tomasi:   max_cnt, min_dist [px], quality_level, block_size [px]  (visual/shi_tomasi_detector.hpp)
//       orb:          n_features, scale_factor, n_levels, fast_threshold [grey levels], edge_threshold [px]
//       superpoint:   weights (ONNX file; relative = to the working directory, else beside the config file),
//                     input_width, input_height [px], max_keypoints, confidence_threshold, nms_radius [px],
//                     border [px], threads, min_keypoints (floor below the threshold; 0 = off), grid_cols,
//                     grid_rows (spread over a grid of the image; 0 = off)
//     tracker:        max_features, min_distance [px], flow_window [px], flow_levels, flow_iterations,
//                     flow_epsilon [px], min_eigenvalue (LK's minEigThreshold), forward_backward (bool),
//                     forward_backward_px [px], border_px [px],
//                     ransac (bool), ransac_threshold_px [px at virtual_focal_px], ransac_confidence,
//                     virtual_focal_px [px], clahe (off | always | when_dark), clahe_clip, clahe_tiles,
//                     dark_mean [grey levels], async_detection (bool), detect_below, detect_interval_s [s],
//                     detect_urgent_below, top_up_below, top_up_min_eigenvalue (visual/feature_tracker.hpp)
//     depth:          window_s [s], voxel_size [m], grid_resolution_deg [deg], neighbour_cells [cells],
//                     max_depth_spread [m], min_depth [m], max_depth [m], min_incidence_cos
//                                                                              (visual/depth_association.hpp)
// One bind function per sub-section in visual_config_io.cpp, one field in VisualConfig.
// Lives in its own library (drover_io_visual) so that the readers do not depend on the visual module.
#include <string>
#include <vector>

#include "visual/depth_association.hpp"
#include "visual/detector_factory.hpp"
#include "visual/feature_tracker.hpp"

namespace drover::io {

struct VisualConfig {
  visual::DetectorConfig detector;
  visual::FeatureTrackerConfig tracker;
  visual::DepthAssociationConfig depth;
};

// Throws IoError (file, line, key) for a missing file, invalid YAML, unknown key or bad value, and when a
// sub-section fails its Config::validate() (naming the file, the sub-section's line and the section).
// A relative SuperPoint weights path is the working directory's, else the one beside the config file, else the first
// of `also_look_in` that holds it (drover_ros: the repository, since a node's working directory is ~/.ros).
VisualConfig loadVisualConfig(const std::string& yaml_path, const std::vector<std::string>& also_look_in = {});

}  // namespace drover::io
