#include "io/image_file_io.hpp"

#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/error.hpp"

namespace drover::io {

cv::Mat readGreyImage(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail(path, "", "image file not found");
  cv::Mat m;
  try {
    m = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    fail(path, "", std::string("cannot decode image: ") + e.err);
  }
  if (m.empty()) fail(path, "", "not a readable image");
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 256.0);
  if (m.depth() != CV_8U) fail(path, "", "unsupported pixel depth (expected 8 or 16 bit)");
  if (m.channels() == 3) cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
  else if (m.channels() == 4) cv::cvtColor(m, m, cv::COLOR_BGRA2GRAY);
  else if (m.channels() != 1) fail(path, "", "unsupported channel count " + std::to_string(m.channels()));
  return m;
}

void writeImage(const std::string& path, const cv::Mat& image) {
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    fail(path, "", std::string("cannot write image: ") + e.err);
  }
  if (!ok) fail(path, "", "cannot write image");
}

}  // namespace drover::io
