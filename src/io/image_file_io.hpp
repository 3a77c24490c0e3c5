#pragma once
// Image files for the readers and the visual front end's tools (drover features detect, benches, tests):
// OpenCV imgcodecs stays in io, the visual module only sees cv::Mat.
#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>

namespace drover::io {

// Largest image the readers decode [px]: a header that claims more is refused before OpenCV allocates the
// pixels (or prints its own assertion). 2^26 = 67 Mpx, e.g. 8192 x 8192, beyond any camera we read.
constexpr std::int64_t kMaxImagePixels = std::int64_t{1} << 26;

// Width and height [px] from the header of PNG or JPEG bytes (a file's first bytes are enough); std::nullopt for
// other formats or when the bytes end before the size.
std::optional<std::pair<std::int64_t, std::int64_t>> imageHeaderSize(const unsigned char* data, std::size_t size);
// "" when the header's size is acceptable (or unknown), else why not ("header claims 100000x100000 px, ...").
std::string imageHeaderProblem(const unsigned char* data, std::size_t size);

// An image file decoded as stored (cv::IMREAD_UNCHANGED). Throws IoError naming the file when it is missing,
// its header claims more than kMaxImagePixels or a zero size, or it cannot be decoded. Never empty.
cv::Mat decodeImageFile(const std::string& path);

// Reads an image file as 8-bit grey (CV_8UC1): colour images are converted (OpenCV's BGR->grey weights), 16-bit
// images scaled by 1/256. Throws IoError naming the file when it is missing or not a readable image.
cv::Mat readGreyImage(const std::string& path);

// Writes an image (PNG, JPEG... by the extension). Throws IoError naming the file when it cannot be written.
void writeImage(const std::string& path, const cv::Mat& image);

}  // namespace drover::io
