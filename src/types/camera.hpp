#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "types/time.hpp"

namespace drover {

// An 8-bit image, row-major and tightly packed (stride = width * channels). A plain struct rather than
// cv::Mat so that the core stays free of OpenCV headers; the visual module wraps it without copying.
struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;  // 1 = mono8, 3 = bgr8 (colour images are always stored as BGR)
  std::vector<std::uint8_t> data;

  bool empty() const { return data.empty(); }
};

struct CameraFrame {
  Time t = 0;       // [ns] exposure mid-point as the dataset reports it
  int camera_id = 0;
  Image image;
  std::string source;  // file or bag record the image came from, for error messages and overlays
};

}  // namespace drover
