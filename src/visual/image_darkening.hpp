#pragma once
// A low-light version of an image, for the detector comparison of dark scenes (the paper's Fig. 4 argument):
// the exposure is scaled and a camera's noise added, so that a detector sees what a dark frame looks like, not
// just a dimmer copy of a bright one.
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace drover::visual {

struct DarkeningConfig {
  double scale = 0.25;           // exposure factor: the mean intensity becomes `scale` of the original (before noise)
  double shot_gain = 1.0;        // [grey levels per photo-electron]: shot-noise variance = shot_gain * signal [DN^2]
  double read_sigma = 2.0;       // [grey levels] Gaussian read noise
  std::uint64_t seed = 1;        // the same seed gives the same noise
  std::string validate() const;  // empty = valid
};

// out = clamp(round(s I + sqrt(g s I) n1 + sigma n2), 0, 255), n1, n2 ~ N(0, 1) per pixel (shot noise in its
// Gaussian approximation). image: CV_8UC1; throws std::invalid_argument otherwise or on an invalid config.
cv::Mat darkenImage(const cv::Mat& image, const DarkeningConfig& config);

}  // namespace drover::visual
