#pragma once
// A small Shi-Tomasi detector for the visual tests (cv::goodFeaturesToTrack, as VINS-Mono), so that the tracker's
// tests do not depend on the detector implementations; optionally slow, to exercise asynchronous detection.
#include <atomic>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <thread>
#include <utility>
#include <vector>

#include "visual/keypoint_detector.hpp"

namespace drover::visual::testing {

class GfttDetector : public KeypointDetector {
 public:
  explicit GfttDetector(double min_distance = 30, int delay_ms = 0)
      : min_distance_(min_distance), delay_ms_(delay_ms) {}
  Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) override {
    ++calls;
    if (delay_ms_ > 0) std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms_));
    Keypoints k;
    if (max_count <= 0) return k;
    cv::goodFeaturesToTrack(image, k.points, max_count, 0.01, min_distance_, mask);
    k.scores.assign(k.points.size(), 1.0f);
    const std::lock_guard<std::mutex> lock(mutex);
    history.push_back({image.clone(), k.points});
    return k;
  }
  std::string name() const override { return "test-gftt"; }
  bool paced() const override { return slow; }
  bool slow = false;  // stands for a slow detector (SuperPoint) in the pacing tests; set before tracking
  std::atomic<int> calls = 0;
  std::mutex mutex;
  std::vector<std::pair<cv::Mat, std::vector<cv::Point2f>>> history;  // (image, points) of every call

 private:
  double min_distance_;
  int delay_ms_;
};

}  // namespace drover::visual::testing
