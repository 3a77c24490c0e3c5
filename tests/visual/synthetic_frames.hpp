#pragma once
// Synthetic image sequences with exactly known motion for the tracker tests. The texture is a sum of Gaussian
// blobs (random centres on a jittered 6 px grid, sigma 2-4 px, random signed amplitude) evaluated analytically at
// every pixel, so a view shifted by a sub-pixel amount is exact (no interpolation error; only 8-bit rounding).
#include <cmath>
#include <opencv2/core.hpp>
#include <vector>

namespace drover::visual::testing {

class BlobCanvas {
 public:
  BlobCanvas(int width, int height, unsigned seed) : cols_(width / kCell + 1), rows_(height / kCell + 1) {
    cv::RNG rng(seed);
    blobs_.resize(static_cast<std::size_t>(cols_) * rows_);
    for (int r = 0; r < rows_; ++r)
      for (int c = 0; c < cols_; ++c)
        blobs_[static_cast<std::size_t>(r) * cols_ + c] = {(c + rng.uniform(0.0, 1.0)) * kCell,
                                                           (r + rng.uniform(0.0, 1.0)) * kCell,
                                                           rng.uniform(2.0, 4.0), rng.uniform(-1.0, 1.0)};
  }
  // Brightness at canvas point (x, y): 128 + 45 * sum of blobs.
  double value(double x, double y) const {
    const int c0 = static_cast<int>(std::floor(x / kCell)), r0 = static_cast<int>(std::floor(y / kCell));
    double v = 0;
    for (int r = r0 - 2; r <= r0 + 2; ++r)
      for (int c = c0 - 2; c <= c0 + 2; ++c) {
        if (r < 0 || c < 0 || r >= rows_ || c >= cols_) continue;
        const Blob& b = blobs_[static_cast<std::size_t>(r) * cols_ + c];
        const double dx = x - b.x, dy = y - b.y;
        v += b.amplitude * std::exp(-(dx * dx + dy * dy) / (2 * b.sigma * b.sigma));
      }
    return 128 + 45 * v;
  }

 private:
  static constexpr int kCell = 6;
  struct Blob {
    double x, y, sigma, amplitude;
  };
  int cols_, rows_;
  std::vector<Blob> blobs_;
};

inline BlobCanvas texture(int width, int height, unsigned seed) { return BlobCanvas(width, height, seed); }

// Paints the pixels of `rect` in `image` (CV_8UC1) with `canvas` moved by `shift` [px] and cropped at `origin`.
inline void paint(cv::Mat& image, const BlobCanvas& canvas, cv::Point2d shift, cv::Rect rect,
                  cv::Point2d origin = {100, 100}) {
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    for (int x = rect.x; x < rect.x + rect.width; ++x)
      image.at<unsigned char>(y, x) =
          cv::saturate_cast<unsigned char>(canvas.value(x + origin.x - shift.x, y + origin.y - shift.y));
}

// The view of `canvas` with its content moved by `shift` [px], cropped at `origin`: pixel p shows canvas point
// p + origin - shift.
inline cv::Mat view(const BlobCanvas& canvas, cv::Point2d shift, cv::Size size, cv::Point2d origin = {100, 100}) {
  cv::Mat out(size, CV_8UC1);
  paint(out, canvas, shift, cv::Rect(0, 0, size.width, size.height), origin);
  return out;
}

}  // namespace drover::visual::testing
