#include "visual/keypoint_coverage.hpp"

#include <stdexcept>
#include <string>

namespace drover::visual {

double gridCoverage(const std::vector<cv::Point2f>& points, cv::Size image, int cols, int rows) {
  if (image.width <= 0 || image.height <= 0) throw std::invalid_argument("gridCoverage: empty image size");
  if (cols < 1 || rows < 1)
    throw std::invalid_argument("gridCoverage: grid must be at least 1x1, got " + std::to_string(cols) + "x" +
                                std::to_string(rows));
  std::vector<char> hit(static_cast<std::size_t>(cols) * rows, 0);
  for (const cv::Point2f& p : points) {
    // Pixel centres are integers: pixel i covers [i - 0.5, i + 0.5).
    const double fx = (p.x + 0.5) / image.width, fy = (p.y + 0.5) / image.height;
    if (!(fx >= 0 && fx < 1 && fy >= 0 && fy < 1)) continue;
    hit[static_cast<std::size_t>(fy * rows) * cols + static_cast<std::size_t>(fx * cols)] = 1;
  }
  int n = 0;
  for (char h : hit) n += h;
  return static_cast<double>(n) / hit.size();
}

}  // namespace drover::visual
