#include "visual/superpoint_postprocess.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "visual/detector_input.hpp"

namespace drover::visual {
namespace {

constexpr int kCell = 8;          // SuperPoint's encoder downsamples by 8
constexpr int kDetChannels = 65;  // 64 pixels of a cell + the dustbin
constexpr int kDescChannels = 256;

void checkBlob(const cv::Mat& m, const char* name, int channels, int hc, int wc) {
  const bool ok = m.type() == CV_32F && m.dims == 4 && m.size[0] == 1 && m.size[1] == channels &&
                  (hc < 0 || (m.size[2] == hc && m.size[3] == wc)) && m.isContinuous();
  if (!ok)
    throw std::invalid_argument(std::string("superpoint: output '") + name + "' must be a CV_32F blob 1x" +
                                std::to_string(channels) + "xH/8xW/8" +
                                (hc < 0 ? "" : " (" + std::to_string(hc) + "x" + std::to_string(wc) + ")") + ", got " +
                                blobShape(m) + " " + matTypeName(m.type()));
}

// Plane c of a 1xCxHxW blob as an HcxWc matrix header (no copy).
cv::Mat plane(const cv::Mat& blob, int c) {
  return cv::Mat(blob.size[2], blob.size[3], CV_32F, const_cast<float*>(blob.ptr<float>(0, c)));
}

}  // namespace

std::string SuperPointPostConfig::validate() const {
  if (!(confidence_threshold > 0 && confidence_threshold < 1))
    return "superpoint.confidence_threshold must be in (0, 1), got " + std::to_string(confidence_threshold);
  if (nms_radius < 0) return "superpoint.nms_radius must be >= 0 px, got " + std::to_string(nms_radius);
  if (border < 0) return "superpoint.border must be >= 0 px, got " + std::to_string(border);
  if (min_keypoints < 0) return "superpoint.min_keypoints must be >= 0, got " + std::to_string(min_keypoints);
  if (grid_cols < 0 || grid_rows < 0 || (grid_cols == 0) != (grid_rows == 0))
    return "superpoint.grid_cols and grid_rows must both be >= 1, or both 0 (off), got " + std::to_string(grid_cols) +
           " x " + std::to_string(grid_rows);
  return {};
}

SuperPointPostprocessor::SuperPointPostprocessor(const SuperPointPostConfig& config) : config_(config) {
  if (std::string err = config_.validate(); !err.empty()) throw std::invalid_argument(err);
}

// Steps 1-2: the softmax is taken plane by plane (vectorised by OpenCV), with the per-cell maximum subtracted for
// numerical safety. Step 3 (collectCandidates): only unmasked pixels at or above `thr` become candidates.
void SuperPointPostprocessor::softmax(const cv::Mat& semi) {
  const int hc = semi.size[2], wc = semi.size[3];
  plane(semi, 0).copyTo(max_logit_);
  for (int c = 1; c < kDetChannels; ++c) cv::max(max_logit_, plane(semi, c), max_logit_);
  exp_.create(kDetChannels * hc, wc, CV_32F);
  sum_exp_.create(hc, wc, CV_32F);
  sum_exp_.setTo(0.0f);
  for (int c = 0; c < kDetChannels; ++c) {
    cv::Mat e = exp_.rowRange(c * hc, (c + 1) * hc);
    cv::subtract(plane(semi, c), max_logit_, tmp_);
    cv::exp(tmp_, e);
    sum_exp_ += e;
  }
}

void SuperPointPostprocessor::collectCandidates(int hc, int wc, float thr, const cv::Mat& mask) {
  candidates_.clear();
  for (int c = 0; c < kDetChannels - 1; ++c) {
    const int dx = c % kCell, dy = c / kCell;
    for (int cy = 0; cy < hc; ++cy) {
      const float* e = exp_.ptr<float>(c * hc + cy);
      const float* s = sum_exp_.ptr<float>(cy);
      for (int cx = 0; cx < wc; ++cx) {
        const float p = e[cx] / s[cx];
        if (p < thr) continue;
        const int x = kCell * cx + dx, y = kCell * cy + dy;
        if (!mask.empty() && mask.at<uchar>(y, x) == 0) continue;
        candidates_.push_back({p, x, y});
      }
    }
  }
}

// Step 4-5: the demo's grid NMS (nms_fast): candidates in decreasing score, each survivor blanks its
// (2r+1)x(2r+1) window in an occupancy grid, and a candidate on a blanked pixel is dropped. Ties are broken by
// row, then column, so the result does not depend on the sort implementation.
void SuperPointPostprocessor::suppress(int width, int height) {
  std::sort(candidates_.begin(), candidates_.end(), [](const Candidate& a, const Candidate& b) {
    if (a.score != b.score) return a.score > b.score;
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  const int r = config_.nms_radius;
  suppressed_.create(height + 2 * r, width + 2 * r, CV_8U);
  suppressed_.setTo(0);
  kept_.clear();
  const int b = config_.border;
  for (const Candidate& cand : candidates_) {
    if (suppressed_.at<uchar>(cand.y + r, cand.x + r)) continue;
    suppressed_(cv::Rect(cand.x, cand.y, 2 * r + 1, 2 * r + 1)).setTo(1);
    // Border removal after NMS, as in the demo: a border point still suppresses its neighbours.
    if (cand.x < b || cand.y < b || cand.x >= width - b || cand.y >= height - b) continue;
    kept_.push_back(cand);
  }
}

// Step 5's spread: kept_ (strongest first) reordered by each point's rank within its grid cell, equal ranks by score
// (a stable sort), so that a top-k takes the best of every cell before the second of any.
void SuperPointPostprocessor::spread(int width, int height) {
  const int cols = config_.grid_cols, rows = config_.grid_rows;
  if (cols == 0 || kept_.size() < 2) return;
  std::vector<int> taken(static_cast<std::size_t>(cols) * rows, 0);
  ranked_.clear();
  for (const Candidate& c : kept_) {
    const int cell = (c.y * rows / height) * cols + c.x * cols / width;
    ranked_.push_back({taken[cell]++, c});
  }
  std::stable_sort(ranked_.begin(), ranked_.end(),
                   [](const Ranked& a, const Ranked& b) { return a.rank < b.rank; });
  for (std::size_t i = 0; i < kept_.size(); ++i) kept_[i] = ranked_[i].candidate;
}

// Step 6.
void SuperPointPostprocessor::sampleDescriptors(const cv::Mat& desc, Keypoints& out) {
  const int hc = desc.size[2], wc = desc.size[3];
  inv_norm_.create(hc, wc, CV_32F);
  inv_norm_.setTo(0.0f);
  for (int c = 0; c < kDescChannels; ++c) cv::accumulateSquare(plane(desc, c), inv_norm_);
  cv::sqrt(inv_norm_, inv_norm_);
  cv::max(inv_norm_, 1e-12f, inv_norm_);
  cv::divide(1.0f, inv_norm_, inv_norm_);
  const std::size_t plane_size = static_cast<std::size_t>(hc) * wc;
  const float* base = desc.ptr<float>();
  out.descriptors.create(static_cast<int>(out.points.size()), kDescChannels, CV_32F);
  for (int i = 0; i < out.descriptors.rows; ++i) {
    const float u = std::clamp((out.points[i].x - 3.5f) / kCell, 0.0f, static_cast<float>(wc - 1));
    const float v = std::clamp((out.points[i].y - 3.5f) / kCell, 0.0f, static_cast<float>(hc - 1));
    const int u0 = std::min(static_cast<int>(u), wc - 1), v0 = std::min(static_cast<int>(v), hc - 1);
    const int u1 = std::min(u0 + 1, wc - 1), v1 = std::min(v0 + 1, hc - 1);
    const float fu = u - u0, fv = v - v0;
    const std::size_t idx[4] = {static_cast<std::size_t>(v0) * wc + u0, static_cast<std::size_t>(v0) * wc + u1,
                                static_cast<std::size_t>(v1) * wc + u0, static_cast<std::size_t>(v1) * wc + u1};
    const float* n = inv_norm_.ptr<float>();
    const float w[4] = {(1 - fu) * (1 - fv) * n[idx[0]], fu * (1 - fv) * n[idx[1]], (1 - fu) * fv * n[idx[2]],
                        fu * fv * n[idx[3]]};
    float* d = out.descriptors.ptr<float>(i);
    double sq = 0;
    for (int c = 0; c < kDescChannels; ++c) {
      const float* p = base + c * plane_size;
      d[c] = w[0] * p[idx[0]] + w[1] * p[idx[1]] + w[2] * p[idx[2]] + w[3] * p[idx[3]];
      sq += static_cast<double>(d[c]) * d[c];
    }
    const float inv = sq > 0 ? static_cast<float>(1.0 / std::sqrt(sq)) : 0.0f;
    for (int c = 0; c < kDescChannels; ++c) d[c] *= inv;
  }
}

Keypoints SuperPointPostprocessor::run(const cv::Mat& semi, const cv::Mat& desc, const cv::Mat& mask, int max_count) {
  if (max_count < 0)
    throw std::invalid_argument("superpoint: max_count must be >= 0, got " + std::to_string(max_count));
  checkBlob(semi, "semi", kDetChannels, -1, -1);
  const int hc = semi.size[2], wc = semi.size[3];
  if (!desc.empty()) checkBlob(desc, "desc", kDescChannels, hc, wc);
  const int width = kCell * wc, height = kCell * hc;
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.cols != width || mask.rows != height))
    throw std::invalid_argument("superpoint: post-processing mask must be CV_8UC1 " + std::to_string(width) + "x" +
                                std::to_string(height) + ", got " + matTypeName(mask.type()) + " " +
                                std::to_string(mask.cols) + "x" + std::to_string(mask.rows));
  softmax(semi);
  collectCandidates(hc, wc, static_cast<float>(config_.confidence_threshold), mask);
  suppress(width, height);
  const std::size_t at_least = static_cast<std::size_t>(std::min(config_.min_keypoints, max_count));
  const bool fill = kept_.size() < at_least;
  if (fill) {  // step 5's floor: every unmasked pixel is a candidate
    collectCandidates(hc, wc, 0.0f, mask);
    suppress(width, height);
  }
  spread(width, height);
  // By score the above-threshold survivors come first and all stay; spread, every cell's best come first.
  if (fill && kept_.size() > at_least) kept_.resize(at_least);
  Keypoints out;
  const std::size_t n = std::min(kept_.size(), static_cast<std::size_t>(max_count));
  out.points.reserve(n);
  out.scores.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {  // kept_ is already in its order: strongest first, or spread
    out.points.emplace_back(static_cast<float>(kept_[i].x), static_cast<float>(kept_[i].y));
    out.scores.push_back(kept_[i].score);
  }
  if (!desc.empty()) sampleDescriptors(desc, out);
  return out;
}

}  // namespace drover::visual
