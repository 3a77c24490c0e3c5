#include "visual/orb_detector.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "visual/detector_input.hpp"

namespace drover::visual {

std::string OrbConfig::validate() const {
  if (n_features < 1) return "orb.n_features must be >= 1, got " + std::to_string(n_features);
  if (!std::isfinite(scale_factor) || scale_factor <= 1.0) return "orb.scale_factor must be > 1";
  if (n_levels < 1) return "orb.n_levels must be >= 1, got " + std::to_string(n_levels);
  if (fast_threshold < 1 || fast_threshold > 255) return "orb.fast_threshold must be in [1, 255] grey levels";
  if (edge_threshold < 31) return "orb.edge_threshold must be >= 31 px (the descriptor patch)";
  return {};
}

OrbDetector::OrbDetector(const OrbConfig& config) : config_(config) {
  if (std::string err = config_.validate(); !err.empty()) throw std::invalid_argument(err);
  orb_ = cv::ORB::create(config_.n_features, static_cast<float>(config_.scale_factor), config_.n_levels,
                         config_.edge_threshold, 0, 2, cv::ORB::HARRIS_SCORE, 31, config_.fast_threshold);
}

Keypoints OrbDetector::detect(const cv::Mat& image, const cv::Mat& mask, int max_count) {
  checkDetectInput("orb", image, mask, max_count);
  Keypoints out;
  const int n = std::min(max_count, config_.n_features);
  if (n == 0) return out;
  orb_->setMaxFeatures(n);
  orb_->detectAndCompute(image, mask, keypoints_, descriptors_);
  // cv::ORB keeps the best per pyramid level but returns them level by level: sort by response, strongest first.
  std::vector<int> order(keypoints_.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return keypoints_[a].response > keypoints_[b].response; });
  // The mask is honoured by cv::ORB, but a keypoint found on a coarser pyramid level can land a pixel inside a
  // masked region once scaled to level 0: drop those too.
  if (!mask.empty()) {
    std::erase_if(order, [&](int i) {
      const cv::Point p(cvRound(keypoints_[i].pt.x), cvRound(keypoints_[i].pt.y));
      return !p.inside(cv::Rect(0, 0, mask.cols, mask.rows)) || mask.at<uchar>(p) == 0;
    });
  }
  order.resize(std::min<std::size_t>(order.size(), static_cast<std::size_t>(n)));
  out.points.reserve(order.size());
  out.scores.reserve(order.size());
  if (!order.empty()) out.descriptors.create(static_cast<int>(order.size()), descriptors_.cols, descriptors_.type());
  for (std::size_t i = 0; i < order.size(); ++i) {
    const cv::KeyPoint& k = keypoints_[order[i]];
    out.points.push_back(k.pt);
    out.scores.push_back(k.response);
    descriptors_.row(order[i]).copyTo(out.descriptors.row(static_cast<int>(i)));
  }
  return out;
}

}  // namespace drover::visual
