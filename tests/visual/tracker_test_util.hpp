#pragma once
// What the feature tracker's tests share: the frame rate and size, a pinhole camera, the base tracker settings and
// a percentile (tests/visual/test_feature_tracker*.cpp).
#include <algorithm>
#include <vector>

#include "types/time.hpp"
#include "visual/camera_model.hpp"
#include "visual/feature_tracker.hpp"

namespace drover::visual::testing {

inline constexpr Time kFrameNs = 50'000'000;  // 20 Hz
inline const cv::Size kSize(640, 480);

inline CameraModel pinhole() {
  CameraIntrinsics k;
  k.width = kSize.width;
  k.height = kSize.height;
  k.fx = k.fy = 460;
  k.cx = 319.5;
  k.cy = 239.5;
  return CameraModel(k);
}

inline FeatureTrackerConfig baseConfig() {
  FeatureTrackerConfig c;
  c.max_features = 120;
  c.clahe = ClaheMode::kOff;
  return c;
}

inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace drover::visual::testing
