#pragma once
// One place that turns a detector choice into a KeypointDetector: the CLI, the tracker and the pipeline use it.
// Filled from the `visual.detector` section of a platform config by io/visual/visual_config_io.hpp.
#include <memory>
#include <string>

#include "visual/feature_tracker.hpp"
#include "visual/orb_detector.hpp"
#include "visual/shi_tomasi_detector.hpp"
#include "visual/superpoint_detector.hpp"

namespace drover::visual {

enum class DetectorType { kSuperPoint, kShiTomasi, kOrb };

// "superpoint", "shi-tomasi", "orb".
std::string detectorTypeName(DetectorType t);
// The inverse; throws std::invalid_argument naming the allowed names.
DetectorType parseDetectorType(const std::string& name);

struct DetectorConfig {
  DetectorType type = DetectorType::kSuperPoint;  // the paper's front end
  ShiTomasiConfig shi_tomasi;
  OrbConfig orb;
  SuperPointConfig superpoint;
  std::string validate() const;  // the chosen detector's config only (empty = valid)
};

// Throws std::invalid_argument on an invalid config, and (SuperPoint) on missing or malformed weights.
std::unique_ptr<KeypointDetector> makeDetector(const DetectorConfig& config);

}  // namespace drover::visual
