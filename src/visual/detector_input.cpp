#include "visual/detector_input.hpp"

#include <stdexcept>
#include <string>

namespace drover::visual {

std::string matTypeName(int type) { return cv::typeToString(type); }

std::string blobShape(const cv::Mat& m) {
  std::string s;
  for (int i = 0; i < m.dims; ++i) {
    if (i > 0) s += 'x';
    s += std::to_string(m.size[i]);
  }
  return s.empty() ? "empty" : s;
}

void checkDetectInput(const char* detector, const cv::Mat& image, const cv::Mat& mask, int max_count) {
  const std::string who = std::string(detector) + ": ";
  if (image.empty()) throw std::invalid_argument(who + "empty image");
  if (image.type() != CV_8UC1)
    throw std::invalid_argument(who + "image must be CV_8UC1 (8-bit grey), got " + matTypeName(image.type()) +
                                "; convert colour or 16-bit images first");
  if (!mask.empty()) {
    if (mask.type() != CV_8UC1)
      throw std::invalid_argument(who + "mask must be CV_8UC1, got " + matTypeName(mask.type()));
    if (mask.size() != image.size())
      throw std::invalid_argument(who + "mask size " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
                                  " differs from the image size " + std::to_string(image.cols) + "x" +
                                  std::to_string(image.rows));
  }
  if (max_count < 0) throw std::invalid_argument(who + "max_count must be >= 0, got " + std::to_string(max_count));
}

}  // namespace drover::visual
