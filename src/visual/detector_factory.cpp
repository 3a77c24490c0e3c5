#include "visual/detector_factory.hpp"

#include <stdexcept>

namespace drover::visual {

std::string detectorTypeName(DetectorType t) {
  switch (t) {
    case DetectorType::kSuperPoint:
      return "superpoint";
    case DetectorType::kShiTomasi:
      return "shi-tomasi";
    case DetectorType::kOrb:
      return "orb";
  }
  return "unknown";
}

DetectorType parseDetectorType(const std::string& name) {
  if (name == "superpoint") return DetectorType::kSuperPoint;
  if (name == "shi-tomasi") return DetectorType::kShiTomasi;
  if (name == "orb") return DetectorType::kOrb;
  throw std::invalid_argument("unknown detector '" + name + "' (expected superpoint, shi-tomasi or orb)");
}

std::string DetectorConfig::validate() const {
  switch (type) {
    case DetectorType::kSuperPoint:
      return superpoint.validate();
    case DetectorType::kShiTomasi:
      return shi_tomasi.validate();
    case DetectorType::kOrb:
      return orb.validate();
  }
  return "unknown detector type";
}

std::unique_ptr<KeypointDetector> makeDetector(const DetectorConfig& config) {
  switch (config.type) {
    case DetectorType::kSuperPoint:
      return std::make_unique<SuperPointDetector>(config.superpoint);
    case DetectorType::kShiTomasi:
      return std::make_unique<ShiTomasiDetector>(config.shi_tomasi);
    case DetectorType::kOrb:
      return std::make_unique<OrbDetector>(config.orb);
  }
  throw std::invalid_argument("unknown detector type");
}

}  // namespace drover::visual
