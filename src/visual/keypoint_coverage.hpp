#pragma once
// How well keypoints spread over an image: the fraction of the cells of a cols x rows grid that hold at least one
// keypoint (the LVI-SAM paper's Fig. 4 argument: SuperPoint keeps features spread in dark and texture-poor
// scenes where corner detectors cluster or vanish). `drover features detect` reports it on a 16 x 12 grid.
#include <opencv2/core.hpp>
#include <vector>

namespace drover::visual {

// Points outside the image are ignored. Throws std::invalid_argument for an empty size or a grid < 1x1.
double gridCoverage(const std::vector<cv::Point2f>& points, cv::Size image, int cols = 16, int rows = 12);

}  // namespace drover::visual
