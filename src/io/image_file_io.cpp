#include "io/image_file_io.hpp"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "io/error.hpp"

namespace drover::io {
namespace {

std::int64_t be16(const unsigned char* p) { return (std::int64_t{p[0]} << 8) | p[1]; }
std::int64_t be32(const unsigned char* p) { return (be16(p) << 16) | be16(p + 2); }

// PNG: 8-byte signature, then the IHDR chunk (length, "IHDR", width, height as big-endian uint32).
std::optional<std::pair<std::int64_t, std::int64_t>> pngHeaderSize(const unsigned char* d, std::size_t n) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n < 24 || std::memcmp(d, kSignature, 8) != 0 || std::memcmp(d + 12, "IHDR", 4) != 0) return std::nullopt;
  return std::make_pair(be32(d + 16), be32(d + 20));
}

// JPEG: segments after the SOI marker until a start-of-frame (SOF0..SOF15 but DHT C4, JPG C8, DAC CC), whose
// payload is precision (1 byte), height, width (big-endian uint16).
std::optional<std::pair<std::int64_t, std::int64_t>> jpegHeaderSize(const unsigned char* d, std::size_t n) {
  if (n < 4 || d[0] != 0xFF || d[1] != 0xD8) return std::nullopt;
  std::size_t i = 2;
  while (i + 4 <= n) {
    if (d[i] != 0xFF) return std::nullopt;
    const unsigned char marker = d[i + 1];
    if (marker == 0xFF) {  // fill byte
      ++i;
      continue;
    }
    const bool sof = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (sof) {
      if (i + 9 > n) return std::nullopt;
      return std::make_pair(be16(d + i + 7), be16(d + i + 5));
    }
    i += 2 + static_cast<std::size_t>(be16(d + i + 2));
  }
  return std::nullopt;
}

// The first bytes of a file: enough for a PNG header and for JPEG segments before the frame header (EXIF
// thumbnails included).
std::vector<unsigned char> fileHead(const std::string& path) {
  constexpr std::size_t kHead = 256 * 1024;
  std::vector<unsigned char> head(kHead);
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(std::max<std::streamsize>(0, in.gcount())));
  return head;
}

}  // namespace

std::optional<std::pair<std::int64_t, std::int64_t>> imageHeaderSize(const unsigned char* data, std::size_t size) {
  if (auto wh = pngHeaderSize(data, size)) return wh;
  return jpegHeaderSize(data, size);
}

std::string imageHeaderProblem(const unsigned char* data, std::size_t size) {
  const auto wh = imageHeaderSize(data, size);
  if (!wh) return "";
  const auto [w, h] = *wh;
  const std::string claim = "header claims " + std::to_string(w) + "x" + std::to_string(h) + " px";
  if (w <= 0 || h <= 0) return claim + ", an empty image";
  if (w > kMaxImagePixels / h)  // w * h > the limit, without overflowing for 32-bit sizes
    return claim + ", more than the " + std::to_string(kMaxImagePixels) + " px an image may have";
  return "";
}

cv::Mat decodeImageFile(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) fail(path, "", "image file not found");
  const std::vector<unsigned char> head = fileHead(path);
  if (const std::string problem = imageHeaderProblem(head.data(), head.size()); !problem.empty())
    fail(path, "header", problem);
  cv::Mat m;
  try {
    m = cv::imread(path, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    // e.err is OpenCV's one-line reason, without the source location and assertion that e.what() adds.
    fail(path, "", "cannot decode image: " + e.err);
  }
  if (m.empty()) fail(path, "", "cannot decode image");
  return m;
}

cv::Mat readGreyImage(const std::string& path) {
  cv::Mat m = decodeImageFile(path);
  if (m.depth() == CV_16U) m.convertTo(m, CV_8U, 1.0 / 256.0);
  if (m.depth() != CV_8U) fail(path, "", "unsupported pixel depth (expected 8 or 16 bit)");
  if (m.channels() == 3)
    cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
  else if (m.channels() == 4)
    cv::cvtColor(m, m, cv::COLOR_BGRA2GRAY);
  else if (m.channels() != 1)
    fail(path, "", "unsupported channel count " + std::to_string(m.channels()));
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
