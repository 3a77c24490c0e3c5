#pragma once
// Image files for the visual front end's tools (drover features detect, benches, tests): OpenCV imgcodecs stays
// in io, the visual module only sees cv::Mat.
#include <opencv2/core.hpp>
#include <string>

namespace drover::io {

// Reads an image file as 8-bit grey (CV_8UC1): colour images are converted (OpenCV's BGR->grey weights), 16-bit
// images scaled by 1/256. Throws IoError naming the file when it is missing or not a readable image.
cv::Mat readGreyImage(const std::string& path);

// Writes an image (PNG, JPEG... by the extension). Throws IoError naming the file when it cannot be written.
void writeImage(const std::string& path, const cv::Mat& image);

}  // namespace drover::io
