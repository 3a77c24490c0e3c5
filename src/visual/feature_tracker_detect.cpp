// Replenishment of the feature tracker: VINS-Mono's setMask (long tracks first, a disc of min_distance around each
// kept feature) and addPoints, synchronously or with the detector in a worker thread (see feature_tracker.hpp).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "visual/feature_tracker.hpp"

namespace drover::visual {

cv::Mat FeatureTracker::crowdMask(TrackingResult& result) {
  cv::Mat mask(camera_.height(), camera_.width(), CV_8UC1, cv::Scalar(255));
  std::vector<std::size_t> order(tracks_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  // Longest first; equal lengths by id so that the outcome never depends on the sort's stability.
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return tracks_.lengths[a] != tracks_.lengths[b] ? tracks_.lengths[a] > tracks_.lengths[b]
                                                    : tracks_.ids[a] < tracks_.ids[b];
  });
  std::vector<unsigned char> keep(tracks_.size(), 0);
  const int radius = static_cast<int>(std::lround(config_.min_distance));
  for (std::size_t i : order) {
    const cv::Point pixel(static_cast<int>(std::lround(tracks_.pixels[i].x)),
                          static_cast<int>(std::lround(tracks_.pixels[i].y)));
    if (mask.at<unsigned char>(pixel) == 0) {
      ++result.dropped_crowded;
      continue;
    }
    keep[i] = 1;
    if (radius > 0) cv::circle(mask, pixel, radius, cv::Scalar(0), cv::FILLED);
  }
  tracks_.keep(keepFinished(keep, TrackEnd::kCrowded, result));
  result.tracked -= result.dropped_crowded;
  return mask;
}

// Adds detections best first where the mask is free, painting a min_distance disc around each one, so the new
// points keep the distance from live tracks and from each other whatever the detector's own spacing.
void FeatureTracker::addDetections(const std::vector<cv::Point2f>& points, cv::Mat& mask, TrackingResult& result,
                                   bool corner) {
  const int radius = static_cast<int>(std::lround(config_.min_distance));
  for (const cv::Point2f& p : points) {
    if (static_cast<int>(tracks_.size()) >= config_.max_features) break;
    if (!inside(p)) continue;
    const cv::Point pixel(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    if (mask.at<unsigned char>(pixel) == 0) continue;
    const auto xn = camera_.undistort({p.x, p.y});
    if (!xn) continue;
    if (radius > 0) cv::circle(mask, pixel, radius, cv::Scalar(0), cv::FILLED);
    tracks_.ids.push_back(next_id_++);
    tracks_.lengths.push_back(1);
    tracks_.pixels.push_back(p);
    tracks_.normalized.push_back(*xn);
    tracks_.velocity.push_back(Eigen::Vector2d::Zero());
    tracks_.corner.push_back(corner ? 1 : 0);
    ++result.added;
    if (corner) ++result.added_corners;
  }
}

namespace {

// Points asked of the detector for `wanted` new features: more, since the min-distance thinning of
// addDetections() drops some (the detectors do not know min_distance; VINS-Mono passes it to goodFeaturesToTrack).
int detectionCount(int wanted) { return wanted > 0 ? 2 * wanted + 20 : 0; }

// Carries points detected in `first` through `frames` (with the forward-backward check when configured); lost
// points become NaN.
std::vector<cv::Point2f> carry(std::vector<cv::Point2f> points, const cv::Mat& first,
                               const std::vector<cv::Mat>& frames, const FeatureTrackerConfig& config) {
  const cv::Size window(config.flow_window, config.flow_window);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat previous = first;
  for (const cv::Mat& frame : frames) {
    std::vector<cv::Point2f> live, next;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < points.size(); ++i)
      if (std::isfinite(points[i].x)) {
        live.push_back(points[i]);
        index.push_back(i);
      }
    if (live.empty()) break;
    std::vector<unsigned char> status, back_status(live.size(), 1);
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(previous, frame, live, next, status, error, window, config.flow_levels,
                             cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01), 0,
                             config.min_eigenvalue);
    std::vector<cv::Point2f> back = live;
    if (config.forward_backward)
      cv::calcOpticalFlowPyrLK(frame, previous, next, back, back_status, error, window, config.flow_levels,
                               cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01),
                               cv::OPTFLOW_USE_INITIAL_FLOW);
    for (std::size_t k = 0; k < live.size(); ++k) {
      const bool ok = status[k] && back_status[k] && cv::norm(back[k] - live[k]) <= config.forward_backward_px;
      points[index[k]] = ok ? next[k] : cv::Point2f(nan, nan);
    }
    previous = frame;
  }
  return points;
}

}  // namespace

void FeatureTracker::replenish(const cv::Mat& gray, TrackingResult& result) {
  cv::Mat mask = crowdMask(result);
  topUp(gray, mask, result);
  detect(gray, mask, result);
}

// Corners where too few tracks came through the flow into this frame, before the detector's turn: points of a detector
// that LK cannot follow (SuperPoint's on a plain wall) die at the next frame, and would otherwise claim the mask each
// time. Live (asynchronous detection) also where the worker's pass would land too late (detect_sync_below). Not on
// the first frame: the detector has its first say.
void FeatureTracker::topUp(const cv::Mat& gray, cv::Mat& mask, TrackingResult& result) {
  const int live = static_cast<int>(tracks_.size());
  if (!corners_ || !has_previous_ || live >= cornersBelow()) return;
  addDetections(corners_->detect(gray, mask.clone(), detectionCount(config_.max_features - live)).points, mask,
                result, true);
}

int FeatureTracker::cornersBelow() const {
  return std::max(config_.top_up_below, config_.async_detection ? config_.detect_sync_below : 0);
}

void FeatureTracker::detect(const cv::Mat& gray, cv::Mat& mask, TrackingResult& result) {
  // Detect-when-needed: a slow detector (SuperPoint) runs only when the live tracks fall below detect_below.
  const int live = static_cast<int>(tracks_.size());
  const bool enough = config_.detect_below > 0 && live >= config_.detect_below;
  const bool waiting = detector_->paced() && config_.detect_interval_s > 0 && live > 0 &&
                       live >= config_.detect_urgent_below && last_detection_t_ &&
                       toSeconds(result.t - *last_detection_t_) < config_.detect_interval_s;
  if ((enough || waiting) && !(config_.async_detection && job_.valid())) return;
  if (!config_.async_detection || tracks_.size() == 0) {
    if (config_.async_detection && job_.valid()) job_.wait();  // the detector serves one caller at a time
    const int wanted = config_.max_features - static_cast<int>(tracks_.size());
    if (wanted > 0) {
      addDetections(detector_->detect(gray, mask.clone(), detectionCount(wanted)).points, mask, result);
      last_detection_t_ = result.t;
    }
    if (config_.async_detection && job_.valid()) job_.get();  // superseded by the synchronous detection
    frames_since_job_.clear();
    return;
  }
  if (job_.valid()) frames_since_job_.push_back(gray);
  if (job_.valid() && job_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    // Carried to this frame, then only where the current mask leaves room.
    addDetections(carry(job_.get().points, job_gray_, frames_since_job_, config_), mask, result);
  }
  if (!job_.valid() && !waiting && static_cast<int>(tracks_.size()) < config_.max_features) {
    last_detection_t_ = result.t;
    job_gray_ = gray;
    frames_since_job_.clear();
    const int wanted = detectionCount(config_.max_features - static_cast<int>(tracks_.size()));
    KeypointDetector* detector = detector_.get();
    job_ = std::async(std::launch::async,
                      [detector, gray, mask = mask.clone(), wanted] { return detector->detect(gray, mask, wanted); });
  }
}

}  // namespace drover::visual
