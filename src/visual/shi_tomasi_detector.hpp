#pragma once
// Shi-Tomasi corners (Shi & Tomasi, "Good Features to Track", CVPR 1994) as VINS-Mono's and LVI-SAM's
// feature_tracker detect them: cv::goodFeaturesToTrack(MAX_CNT - tracked, quality 0.01, MIN_DIST, mask).
#include <string>

#include "visual/keypoint_detector.hpp"

namespace drover::visual {

struct ShiTomasiConfig {
  int max_cnt = 150;            // at most this many corners per image (VINS MAX_CNT); the caller may ask fewer
  double min_dist = 30.0;       // [px] minimum distance between two corners (VINS MIN_DIST)
  double quality_level = 0.01;  // corners weaker than this fraction of the strongest are dropped (VINS: 0.01)
  int block_size = 3;           // [px] side of the structure-tensor window
  std::string validate() const;  // empty = valid
};

// Scores are the minimal eigenvalue of the structure tensor (OpenCV's cornerMinEigenVal); no descriptors.
class ShiTomasiDetector : public KeypointDetector {
 public:
  explicit ShiTomasiDetector(const ShiTomasiConfig& config = {});  // throws std::invalid_argument if invalid
  Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) override;
  std::string name() const override { return "shi-tomasi"; }
  const ShiTomasiConfig& config() const { return config_; }

 private:
  ShiTomasiConfig config_;
  std::vector<cv::Point2f> corners_;  // reused between frames
  std::vector<float> quality_;
};

}  // namespace drover::visual
