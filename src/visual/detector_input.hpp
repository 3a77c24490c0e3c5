#pragma once
// The precondition every KeypointDetector::detect() checks before touching the image: one place, one wording.
#include <opencv2/core.hpp>

namespace drover::visual {

// Throws std::invalid_argument naming what is wrong: an empty image, an image that is not CV_8UC1 (colour or
// 16-bit images must be converted by the caller), a mask that is not empty and not CV_8UC1 of the image's size, or
// a negative max_count. `detector` prefixes the message ("superpoint: ...").
void checkDetectInput(const char* detector, const cv::Mat& image, const cv::Mat& mask, int max_count);

// OpenCV's name of a Mat type ("CV_8UC3", "CV_16UC1"), for messages.
std::string matTypeName(int type);
// The shape of an n-D blob, "1x65x60x80" ("empty" for none), for messages.
std::string blobShape(const cv::Mat& m);

}  // namespace drover::visual
