#include "visual/shi_tomasi_detector.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "visual/detector_input.hpp"

namespace drover::visual {

std::string ShiTomasiConfig::validate() const {
  if (max_cnt < 1) return "shi_tomasi.max_cnt must be >= 1, got " + std::to_string(max_cnt);
  if (!std::isfinite(min_dist) || min_dist < 0) return "shi_tomasi.min_dist must be >= 0 [px]";
  if (!(quality_level > 0 && quality_level < 1)) return "shi_tomasi.quality_level must be in (0, 1)";
  if (block_size < 3 || block_size % 2 == 0) return "shi_tomasi.block_size must be odd and >= 3";
  return {};
}

ShiTomasiDetector::ShiTomasiDetector(const ShiTomasiConfig& config) : config_(config) {
  if (std::string err = config_.validate(); !err.empty()) throw std::invalid_argument(err);
}

Keypoints ShiTomasiDetector::detect(const cv::Mat& image, const cv::Mat& mask, int max_count) {
  checkDetectInput("shi-tomasi", image, mask, max_count);
  Keypoints out;
  const int n = std::min(max_count, config_.max_cnt);
  if (n == 0) return out;  // goodFeaturesToTrack reads maxCorners <= 0 as "no limit"
  // The overload with cornersQuality returns the corners sorted by quality, strongest first.
  cv::goodFeaturesToTrack(image, corners_, n, config_.quality_level, config_.min_dist, mask, quality_,
                          config_.block_size, 3, false, 0.04);
  out.points = corners_;
  out.scores = quality_;
  return out;
}

}  // namespace drover::visual
