// KLT tracking step of the feature tracker: preprocessing, flow with forward-backward and border checks, and the
// fundamental-matrix RANSAC (VINS-Mono feature_tracker.cpp: readImage, rejectWithF). Replenishment is in
// feature_tracker_detect.cpp.
#include "visual/feature_tracker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>

#include "visual/shi_tomasi_detector.hpp"

namespace drover::visual {

std::string FeatureTrackerConfig::validate() const {
  if (max_features < 1) return "max_features must be >= 1, got " + std::to_string(max_features);
  if (detect_below < 0) return "detect_below must be >= 0, got " + std::to_string(detect_below);
  if (!(detect_interval_s >= 0 && detect_interval_s <= 60))
    return "detect_interval_s must be in [0, 60] s, got " + std::to_string(detect_interval_s);
  if (detect_sync_below < 0) return "detect_sync_below must be >= 0, got " + std::to_string(detect_sync_below);
  if (detect_urgent_below < 0) return "detect_urgent_below must be >= 0, got " + std::to_string(detect_urgent_below);
  if (top_up_below < 0) return "top_up_below must be >= 0, got " + std::to_string(top_up_below);
  if (!(top_up_min_eigenvalue >= 0) || !std::isfinite(top_up_min_eigenvalue))
    return "top_up_min_eigenvalue must be finite and >= 0, got " + std::to_string(top_up_min_eigenvalue);
  if (!(min_distance >= 0)) return "min_distance must be >= 0 px, got " + std::to_string(min_distance);
  if (flow_window < 3 || flow_window % 2 == 0)
    return "flow_window must be odd and >= 3, got " + std::to_string(flow_window);
  if (flow_levels < 0 || flow_levels > 8) return "flow_levels must be in [0, 8], got " + std::to_string(flow_levels);
  if (flow_iterations < 1) return "flow_iterations must be >= 1, got " + std::to_string(flow_iterations);
  if (!(flow_epsilon > 0)) return "flow_epsilon must be > 0, got " + std::to_string(flow_epsilon);
  if (!(min_eigenvalue >= 0) || !std::isfinite(min_eigenvalue))
    return "min_eigenvalue must be finite and >= 0, got " + std::to_string(min_eigenvalue);
  if (!(forward_backward_px > 0)) return "forward_backward_px must be > 0, got " + std::to_string(forward_backward_px);
  if (border_px < 0) return "border_px must be >= 0, got " + std::to_string(border_px);
  if (!(ransac_threshold_px > 0)) return "ransac_threshold_px must be > 0, got " + std::to_string(ransac_threshold_px);
  if (!(ransac_confidence > 0 && ransac_confidence < 1))
    return "ransac_confidence must be in (0, 1), got " + std::to_string(ransac_confidence);
  if (!(virtual_focal_px > 0)) return "virtual_focal_px must be > 0, got " + std::to_string(virtual_focal_px);
  if (!(clahe_clip > 0)) return "clahe_clip must be > 0, got " + std::to_string(clahe_clip);
  if (clahe_tiles < 1) return "clahe_tiles must be >= 1, got " + std::to_string(clahe_tiles);
  if (!(dark_mean >= 0 && dark_mean <= 255)) return "dark_mean must be in [0, 255], got " + std::to_string(dark_mean);
  return {};
}

cv::Mat imageView(const Image& image) {
  if (image.empty() || image.width <= 0 || image.height <= 0 || (image.channels != 1 && image.channels != 3) ||
      image.data.size() != static_cast<std::size_t>(image.width) * image.height * image.channels)
    throw std::invalid_argument("imageView: empty or inconsistent image (" + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + "x" + std::to_string(image.channels) + ", " +
                                std::to_string(image.data.size()) + " bytes)");
  return cv::Mat(image.height, image.width, image.channels == 1 ? CV_8UC1 : CV_8UC3,
                 const_cast<std::uint8_t*>(image.data.data()));
}

void FeatureTracker::Tracks::keep(const std::vector<unsigned char>& keep_mask) {
  std::size_t j = 0;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!keep_mask[i]) continue;
    ids[j] = ids[i];
    lengths[j] = lengths[i];
    pixels[j] = pixels[i];
    normalized[j] = normalized[i];
    velocity[j] = velocity[i];
    corner[j] = corner[i];
    ++j;
  }
  ids.resize(j);
  lengths.resize(j);
  pixels.resize(j);
  normalized.resize(j);
  velocity.resize(j);
  corner.resize(j);
}

FeatureTracker::FeatureTracker(const CameraModel& camera, std::shared_ptr<KeypointDetector> detector,
                               const FeatureTrackerConfig& config)
    : camera_(camera), detector_(std::move(detector)), config_(config) {
  if (const std::string error = config.validate(); !error.empty())
    throw std::invalid_argument("FeatureTrackerConfig: " + error);
  if (!detector_) throw std::invalid_argument("FeatureTracker: null detector");
  if (cornersBelow() > 0) {
    ShiTomasiConfig corners;  // VINS-Mono's goodFeaturesToTrack: quality 0.01, MIN_DIST apart
    corners.max_cnt = config_.max_features;
    corners.min_dist = config_.min_distance;
    corners_ = std::make_unique<ShiTomasiDetector>(corners);
  }
}

FeatureTracker::~FeatureTracker() {
  if (job_.valid()) job_.wait();  // the worker uses detector_; never leave it running
}

bool FeatureTracker::inside(const cv::Point2f& p) const {
  const float b = static_cast<float>(config_.border_px);
  return std::isfinite(p.x) && std::isfinite(p.y) && p.x >= b && p.y >= b && p.x <= camera_.width() - 1 - b &&
         p.y <= camera_.height() - 1 - b;
}

cv::Mat FeatureTracker::preprocess(const cv::Mat& image, TrackingResult& result) const {
  if (image.empty() || image.cols != camera_.width() || image.rows != camera_.height() ||
      (image.type() != CV_8UC1 && image.type() != CV_8UC3))
    throw std::invalid_argument("FeatureTracker::track: image must be CV_8UC1/CV_8UC3 of " +
                                std::to_string(camera_.width()) + "x" + std::to_string(camera_.height()) + ", got " +
                                std::to_string(image.cols) + "x" + std::to_string(image.rows) + " type " +
                                std::to_string(image.type()));
  cv::Mat gray;
  if (image.type() == CV_8UC3)
    cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  else
    gray = image.clone();  // the caller's buffer may change before the next frame
  const bool dark = config_.clahe == ClaheMode::kWhenDark && cv::mean(gray)[0] < config_.dark_mean;
  if (config_.clahe == ClaheMode::kAlways || dark) {
    cv::createCLAHE(config_.clahe_clip, cv::Size(config_.clahe_tiles, config_.clahe_tiles))->apply(gray, gray);
    result.clahe_applied = true;
  }
  return gray;
}

const char* trackEndName(TrackEnd end) {
  switch (end) {
    case TrackEnd::kLostFlow: return "lost_flow";
    case TrackEnd::kForwardBackward: return "rejected_fb";
    case TrackEnd::kBorder: return "rejected_border";
    case TrackEnd::kRansac: return "rejected_ransac";
    case TrackEnd::kCrowded: return "dropped_crowded";
  }
  return "?";
}

std::vector<unsigned char> FeatureTracker::keepFinished(std::vector<unsigned char> keep,
                                                        const std::vector<TrackEnd>& causes,
                                                        TrackingResult& result) const {
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (!keep[i]) {
      result.finished_lengths.push_back(tracks_.lengths[i]);
      result.finished_causes.push_back(causes[i]);
    }
  return keep;
}

std::vector<unsigned char> FeatureTracker::keepFinished(std::vector<unsigned char> keep, TrackEnd cause,
                                                        TrackingResult& result) const {
  const std::vector<TrackEnd> causes(keep.size(), cause);
  return keepFinished(std::move(keep), causes, result);
}

void FeatureTracker::flow(const cv::Mat& gray, double dt, TrackingResult& result) {
  if (tracks_.size() == 0) return;
  const cv::Size window(config_.flow_window, config_.flow_window);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, config_.flow_iterations,
                                  config_.flow_epsilon);
  std::vector<cv::Point2f> current;
  std::vector<unsigned char> status;
  std::vector<float> error;
  flowWithFloors(gray, window, criteria, current, status);
  std::vector<unsigned char> back_status(status.size(), 1);
  std::vector<cv::Point2f> back;
  if (config_.forward_backward) {
    back = tracks_.pixels;  // start the backward flow at the original points (OPTFLOW_USE_INITIAL_FLOW)
    cv::calcOpticalFlowPyrLK(gray, previous_gray_, current, back, back_status, error, window, config_.flow_levels,
                             criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  }
  std::vector<unsigned char> keep(status.size(), 0);
  std::vector<TrackEnd> causes(status.size(), TrackEnd::kLostFlow);
  std::vector<Eigen::Vector2d> previous_normalized = tracks_.normalized;  // for RANSAC
  for (std::size_t i = 0; i < status.size(); ++i) {
    if (!status[i]) {
      ++result.lost_flow;
      continue;
    }
    if (config_.forward_backward &&
        (!back_status[i] || cv::norm(back[i] - tracks_.pixels[i]) > config_.forward_backward_px)) {
      ++result.rejected_fb;
      causes[i] = TrackEnd::kForwardBackward;
      continue;
    }
    const auto xn = inside(current[i]) ? camera_.undistort({current[i].x, current[i].y}) : std::nullopt;
    if (!xn) {
      ++result.rejected_border;
      causes[i] = TrackEnd::kBorder;
      continue;
    }
    keep[i] = 1;
    tracks_.velocity[i] = (*xn - tracks_.normalized[i]) / dt;
    tracks_.normalized[i] = *xn;
    tracks_.pixels[i] = current[i];
    ++tracks_.lengths[i];
  }
  tracks_.keep(keepFinished(keep, causes, result));
  std::size_t j = 0;
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) previous_normalized[j++] = previous_normalized[i];
  previous_normalized.resize(j);
  if (config_.ransac) rejectWithFundamental(previous_normalized, result);
  result.tracked = static_cast<int>(tracks_.size());
}

void FeatureTracker::flowWithFloors(const cv::Mat& gray, const cv::Size& window, const cv::TermCriteria& criteria,
                                    std::vector<cv::Point2f>& current, std::vector<unsigned char>& status) {
  std::vector<float> min_eigenvalues;
  if (std::none_of(tracks_.corner.begin(), tracks_.corner.end(), [](unsigned char c) { return c != 0; })) {  // one floor: exactly the detector-only tracker
    cv::calcOpticalFlowPyrLK(previous_gray_, gray, tracks_.pixels, current, status, min_eigenvalues, window,
                             config_.flow_levels, criteria, 0, config_.min_eigenvalue);
    return;
  }
  // OpenCV fails a point only at the finest level, when that level's minimum eigenvalue (returned with
  // OPTFLOW_LK_GET_MIN_EIGENVALS) is below the threshold: so flow at the lower floor, then the detector's tracks held
  // to theirs, is each track at its own floor (the coarse levels then iterate where they skipped before).
  const double lower = std::min(config_.min_eigenvalue, config_.top_up_min_eigenvalue);
  cv::calcOpticalFlowPyrLK(previous_gray_, gray, tracks_.pixels, current, status, min_eigenvalues, window,
                           config_.flow_levels, criteria, cv::OPTFLOW_LK_GET_MIN_EIGENVALS, lower);
  for (std::size_t i = 0; i < status.size(); ++i) {
    const double floor = tracks_.corner[i] ? config_.top_up_min_eigenvalue : config_.min_eigenvalue;
    if (status[i] && min_eigenvalues[i] < floor) status[i] = 0;
  }
}

void FeatureTracker::rejectWithFundamental(const std::vector<Eigen::Vector2d>& previous, TrackingResult& result) {
  if (tracks_.size() < 8) return;
  // VINS-Mono rejectWithF: points lifted to normalised coordinates and re-projected by a virtual pinhole of focal
  // length F centred on the image, so the threshold is in pixels of a fixed camera whatever the lens.
  const double f = config_.virtual_focal_px, cx = camera_.width() / 2.0, cy = camera_.height() / 2.0;
  std::vector<cv::Point2f> a, b;
  for (std::size_t i = 0; i < tracks_.size(); ++i) {
    a.emplace_back(static_cast<float>(f * previous[i].x() + cx), static_cast<float>(f * previous[i].y() + cy));
    b.emplace_back(static_cast<float>(f * tracks_.normalized[i].x() + cx),
                   static_cast<float>(f * tracks_.normalized[i].y() + cy));
  }
  std::vector<unsigned char> inlier;
  const cv::Mat F =
      cv::findFundamentalMat(a, b, cv::FM_RANSAC, config_.ransac_threshold_px, config_.ransac_confidence, inlier);
  result.ransac_run = true;
  if (F.empty() || inlier.size() != tracks_.size()) {  // degenerate (e.g. no motion): keep everything
    result.inlier_ratio = 1.0;
    return;
  }
  int inliers = 0;
  for (unsigned char s : inlier) inliers += s ? 1 : 0;
  result.rejected_ransac = static_cast<int>(tracks_.size()) - inliers;
  result.inlier_ratio = static_cast<double>(inliers) / static_cast<double>(tracks_.size());
  tracks_.keep(keepFinished(inlier, TrackEnd::kRansac, result));
}

TrackingResult FeatureTracker::track(Time t, const cv::Mat& image) {
  const auto start = std::chrono::steady_clock::now();
  if (has_previous_ && t <= previous_t_)
    throw std::invalid_argument("FeatureTracker::track: time " + std::to_string(t) + " ns does not follow " +
                                std::to_string(previous_t_) + " ns");
  TrackingResult result;
  result.t = t;
  const cv::Mat gray = preprocess(image, result);
  if (has_previous_) flow(gray, static_cast<double>(t - previous_t_) * 1e-9, result);
  replenish(gray, result);
  previous_gray_ = gray;
  previous_t_ = t;
  has_previous_ = true;
  result.features.reserve(tracks_.size());
  for (std::size_t i = 0; i < tracks_.size(); ++i)
    result.features.push_back(
        {tracks_.ids[i], tracks_.lengths[i], tracks_.pixels[i], tracks_.normalized[i], tracks_.velocity[i],
         tracks_.corner[i] != 0});
  result.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace drover::visual
