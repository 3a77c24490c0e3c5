#pragma once
// ORB keypoints and binary descriptors (Rublee et al., ICCV 2011) through cv::ORB: FAST corners on an image
// pyramid ranked by the Harris response, rBRIEF descriptors.
#include <opencv2/features2d.hpp>
#include <string>

#include "visual/keypoint_detector.hpp"

namespace drover::visual {

struct OrbConfig {
  int n_features = 500;       // at most this many keypoints per image; the caller may ask fewer
  double scale_factor = 1.2;  // pyramid decimation ratio (> 1)
  int n_levels = 8;           // pyramid levels
  int fast_threshold = 20;    // [grey levels] FAST intensity threshold
  int edge_threshold = 31;    // [px] border without keypoints (>= the descriptor patch size, 31)
  std::string validate() const;  // empty = valid
};

// Scores are the Harris responses cv::ORB ranks by; descriptors CV_8U, 32 bytes per row; points at level-0 pixels.
class OrbDetector : public KeypointDetector {
 public:
  explicit OrbDetector(const OrbConfig& config = {});  // throws std::invalid_argument if invalid
  Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) override;
  std::string name() const override { return "orb"; }
  const OrbConfig& config() const { return config_; }

 private:
  OrbConfig config_;
  cv::Ptr<cv::ORB> orb_;
  std::vector<cv::KeyPoint> keypoints_;  // reused between frames
  cv::Mat descriptors_;
};

}  // namespace drover::visual
