#include "visual/image_darkening.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "visual/detector_input.hpp"

namespace drover::visual {

std::string DarkeningConfig::validate() const {
  if (!(scale > 0 && scale <= 1)) return "darkening scale must be in (0, 1], got " + std::to_string(scale);
  if (!(shot_gain >= 0 && std::isfinite(shot_gain))) return "darkening shot_gain must be >= 0";
  if (!(read_sigma >= 0 && std::isfinite(read_sigma))) return "darkening read_sigma must be >= 0";
  return {};
}

cv::Mat darkenImage(const cv::Mat& image, const DarkeningConfig& config) {
  checkDetectInput("darken", image, cv::Mat(), 0);
  if (std::string err = config.validate(); !err.empty()) throw std::invalid_argument(err);
  cv::RNG rng(config.seed);
  cv::Mat out(image.size(), CV_8UC1);
  for (int y = 0; y < image.rows; ++y) {
    const uchar* src = image.ptr<uchar>(y);
    uchar* dst = out.ptr<uchar>(y);
    for (int x = 0; x < image.cols; ++x) {
      const double signal = config.scale * src[x];
      const double v =
          signal + std::sqrt(config.shot_gain * signal) * rng.gaussian(1.0) + config.read_sigma * rng.gaussian(1.0);
      dst[x] = cv::saturate_cast<uchar>(std::lround(v));
    }
  }
  return out;
}

}  // namespace drover::visual
