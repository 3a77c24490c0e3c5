#include "visual/tracking_summary.hpp"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace drover::visual {

void TrackingSummaryBuilder::add(const TrackingResult& r) {
  if (frames_ > 0 && r.tracked >= 50) ++ge50_;
  ++frames_;
  features_ += static_cast<double>(r.features.size());
  new_ += r.added;
  for (int length : r.finished_lengths) lengths_ += length;
  if (!r.features.empty()) {
    double live = 0;
    for (const TrackedFeature& f : r.features) live += f.track_length;
    live_lengths_ += live / static_cast<double>(r.features.size());
  }
  finished_ += r.finished_lengths.size();
  for (std::size_t i = 0; i < r.finished_causes.size() && i < r.finished_lengths.size(); ++i) {
    const auto cause = static_cast<std::size_t>(r.finished_causes[i]);
    ++ended_by_[cause];
    lengths_by_[cause] += r.finished_lengths[i];
  }
  if (r.ransac_run) {
    inliers_ += r.inlier_ratio;
    ++ransac_frames_;
  }
  ms_.push_back(r.ms);
}

TrackingSummary TrackingSummaryBuilder::summary() const {
  TrackingSummary s;
  s.frames = frames_;
  if (frames_ == 0) return s;
  const double n = static_cast<double>(frames_);
  s.mean_features = features_ / n;
  s.mean_new = new_ / n;
  s.finished_tracks = finished_;
  s.mean_track_length = finished_ > 0 ? lengths_ / static_cast<double>(finished_) : 0;
  s.mean_live_length = live_lengths_ / n;
  s.ended_by = ended_by_;
  for (std::size_t c = 0; c < ended_by_.size(); ++c)
    s.mean_length_by[c] = ended_by_[c] > 0 ? lengths_by_[c] / static_cast<double>(ended_by_[c]) : 0;
  s.mean_inlier_ratio = ransac_frames_ > 0 ? inliers_ / static_cast<double>(ransac_frames_) : 1;
  std::vector<double> ms = ms_;
  std::sort(ms.begin(), ms.end());
  for (double m : ms) s.mean_ms += m / n;
  s.p95_ms = ms[static_cast<std::size_t>(0.95 * static_cast<double>(ms.size() - 1))];
  s.max_ms = ms.back();
  s.fraction_tracked_ge_50 = frames_ > 1 ? static_cast<double>(ge50_) / static_cast<double>(frames_ - 1) : 0;
  return s;
}

cv::Mat drawTracks(const cv::Mat& image, const TrackingResult& result, double focal_px) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  for (const TrackedFeature& f : result.features) {
    const double a = std::min(1.0, (f.track_length - 1) / 19.0);  // 0 new .. 1 long
    const cv::Scalar colour(0, 255 * std::min(1.0, 2 * a), 255 * std::min(1.0, 2 * (1 - a)));  // BGR
    const cv::Point2f tip = f.pixel + cv::Point2f(static_cast<float>(f.velocity.x() * 0.1 * focal_px),
                                                  static_cast<float>(f.velocity.y() * 0.1 * focal_px));
    cv::line(out, f.pixel, tip, colour, 1, cv::LINE_AA);
    cv::circle(out, f.pixel, 2, colour, cv::FILLED, cv::LINE_AA);
  }
  char caption[160];
  std::snprintf(caption, sizeof caption, "features %zu  tracked %d  new %d  ransac %.2f  %.1f ms%s",
                result.features.size(), result.tracked, result.added, result.inlier_ratio, result.ms,
                result.clahe_applied ? "  clahe" : "");
  cv::putText(out, caption, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
  cv::putText(out, caption, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return out;
}

}  // namespace drover::visual
