#pragma once
// KLT feature tracker with VINS-Mono's feature_tracker semantics (Qin et al., "VINS-Mono", T-RO 2018, Sec. IV-A;
// feature_tracker.cpp): pyramidal Lucas-Kanade flow from the previous frame, a border check, outlier rejection by a
// fundamental-matrix RANSAC on undistorted points reprojected with a virtual focal length, persistent ids and track
// lengths, and replenishment by a KeypointDetector inside a mask that keeps `min_distance` around live tracks (long
// tracks claim their neighbourhood first, as VINS-Mono's setMask). Added here: a forward-backward flow check (as
// VINS-Fusion's FLOW_BACK), optional CLAHE (always or only on dark frames), and asynchronous detection so that a
// slow detector (SuperPoint, ~0.3-0.6 s a frame on a laptop CPU) does not hold back the camera rate; and a corner
// top-up (Shi-Tomasi, each track at its own LK floor) where the detector leaves the tracks short (top_up_below).
//
// Synchronous mode (the default; tests and evaluation): the same frames give the same tracks, bit for bit.
// Asynchronous mode: the detector runs in one worker thread on frame k with the mask of frame k; when its points
// are ready (at frame j > k) they are carried by the flow through the frames k+1..j, filtered by the mask of frame
// j, and added. Results then depend on timing. The first detection (no live tracks) is always synchronous.
#include <Eigen/Core>
#include <cstdint>
#include <future>
#include <memory>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "types/camera.hpp"
#include "visual/camera_model.hpp"
#include "visual/keypoint_detector.hpp"

namespace drover::visual {

enum class ClaheMode { kOff, kAlways, kWhenDark };

struct FeatureTrackerConfig {
  int max_features = 150;           // live tracks kept (VINS-Mono max_cnt)
  double min_distance = 30;         // [px] between features (VINS-Mono min_dist)
  int flow_window = 21;             // [px] LK window side (VINS-Mono: 21)
  int flow_levels = 3;              // pyramid levels above the image (cv::calcOpticalFlowPyrLK maxLevel)
  int flow_iterations = 30;         // LK iterations per level
  double flow_epsilon = 0.01;       // [px] LK convergence
  // cv::calcOpticalFlowPyrLK's minEigThreshold: a track is lost where the smallest eigenvalue of its window's
  // gradient matrix falls below this. OpenCV's units: per pixel of the window, from Scharr derivatives scaled by 2^-20,
  // so a window whose weakest direction has an RMS gradient of g grey levels a pixel gives g^2 / 1024, and image noise
  // of sigma grey levels alone about 2.3e-4 sigma^2 (Scharr's noise gain 236 sigma^2 / 2^20). Two kinds of track fall
  // below it: windows that see only noise (a plain wall; LK follows the noise) and windows on one straight edge,
  // along which LK slides (the aperture problem). Measured over the tracked features of the simulated camera
  // (p10 / p50): textured surfaces 5.5e-3 / 9e-3, textureless ones 3e-4 / 4.5e-4 (noise: its shot noise of ~2 grey
  // levels at mid-grey gives ~9e-4); EuRoC's real frames 1.5e-3 / 1.3e-2. So it is a noise floor in grey levels,
  // and a platform setting: the shipped platform files keep OpenCV's default, and drover run's drover preset raises
  // it to 2e-3 for SuperPoint's tracks (apps/drover/run_preset.cpp; bench/RESULTS.md). A camera at high gain, or
  // with CLAHE on its dark frames, has more noise in grey levels and needs a higher floor (it goes with sigma^2).
  double min_eigenvalue = 1e-4;
  bool forward_backward = true;     // track back and drop points that do not return
  double forward_backward_px = 0.5;  // [px] largest forward-backward distance kept
  int border_px = 1;                // [px] points closer to the image edge are dropped (VINS-Mono inBorder)
  bool ransac = true;               // fundamental-matrix RANSAC (VINS-Mono rejectWithF)
  double ransac_threshold_px = 1.0;  // [px at the virtual focal length] (VINS-Mono F_threshold)
  double ransac_confidence = 0.99;
  double virtual_focal_px = 460;    // [px] focal length of the virtual camera RANSAC works in (VINS-Mono FOCAL_LENGTH)
  ClaheMode clahe = ClaheMode::kWhenDark;
  double clahe_clip = 3.0;          // CLAHE clip limit (VINS-Mono: 3.0)
  int clahe_tiles = 8;              // CLAHE tiles per side (VINS-Mono: 8x8)
  double dark_mean = 60;            // [grey levels] kWhenDark: CLAHE when the frame's mean is below this
  bool async_detection = false;     // run the detector in a worker thread (see above)
  // With async_detection: fewer live tracks than this and the corner top-up (below) fills the frame at once, at
  // top_up_min_eigenvalue, while the worker's pass goes on. That pass lands 1-2 frames later, and where tracks die
  // fast (the farm's jolting stretch) the live VIS ran out of them first: at sensor rate it reset on "only 7 features
  // tracked (< 8)" again and again there, with an estimate on 17 % of the stretch's frames against 90 % in the
  // replay. SuperPoint on the frame itself instead took 300-570 ms a frame beside the LIS on 2 cores and the VIS
  // dropped 687 frames (bench/RESULTS.md). 20 is where the LIS stops taking the VIS (vis_fusion.min_features).
  // 0: off.
  int detect_sync_below = 20;       // [tracks]
  int detect_below = 0;             // detect only when fewer live tracks than this (0, or >= max_features: whenever
                                    // below max_features, as VINS-Mono); the VIS's policy for a slow detector
  // A slow detector that finds fewer features than detect_below (SuperPoint on plain walls) would otherwise run at
  // every frame: after a detection the next one waits detect_interval_s of image time, unless the live tracks fall
  // below detect_urgent_below. 0 = no wait. Only a detector that says it is paced (KeypointDetector::paced:
  // SuperPoint) is held; the millisecond ones ignore these two keys.
  double detect_interval_s = 0;     // [s]
  int detect_urgent_below = 0;      // [tracks]
  // Corner top-up. When fewer than top_up_below tracks come through the flow into a frame, Shi-Tomasi corners
  // (VINS-Mono's goodFeaturesToTrack, quality 0.01, min_distance apart) fill the free mask up to max_features before
  // the detector's turn, on the current frame and synchronously (a few ms). Their tracks keep top_up_min_eigenvalue
  // as their LK floor. 0 = off (the detector alone; the shipped configs and the presets).
  // A floor under the camera's noise (~9.5e-4 for the simulated camera) takes points on straight edges, whose
  // smallest eigenvalue is the noise along the edge: on the simulated white walls 45 % of the corners at 1e-4 lie on
  // the edges where walls meet floor and ceiling, which look the same from anywhere along the passage, so their
  // tracks stand still (0.4 % of the true flow) and tell the VIS it is stopped. With 40 at 1e-4 the drover preset's
  // VIS fell to 0.35x the true speed there on the farm's fault course and took the LIS 11 m off (bench/RESULTS.md).
  int top_up_below = 0;             // [tracks]
  // LK floor of the corners' tracks (min_eigenvalue's units): ~2x the simulated camera's noise alone, as the drover
  // preset's floor for SuperPoint's tracks
  double top_up_min_eigenvalue = 2e-3;
  std::string validate() const;     // empty = valid, else names the bad value
};

// Why a track ended (TrackingResult's counters, one per cause).
enum class TrackEnd { kLostFlow, kForwardBackward, kBorder, kRansac, kCrowded };
inline constexpr int kTrackEndCount = 5;
const char* trackEndName(TrackEnd end);  // "lost_flow", "rejected_fb", "rejected_border", "rejected_ransac", "dropped_crowded"

struct TrackedFeature {
  std::uint64_t id = 0;           // persistent while the feature is tracked, never reused
  int track_length = 0;           // frames this feature has been seen in, 1 on the frame it was detected
  cv::Point2f pixel;              // [px] in the distorted image
  Eigen::Vector2d normalized;     // undistorted normalised coordinates (x / z, y / z)
  Eigen::Vector2d velocity;       // [normalised units / s], from the previous frame; zero for new features
  bool corner = false;            // from the corner top-up (FeatureTrackerConfig::top_up_below), not the detector
};

struct TrackingResult {
  Time t = 0;
  std::vector<TrackedFeature> features;  // every live feature after this frame
  int tracked = 0;            // features carried over from the previous frame (after every check)
  int added = 0;              // new features from the detector and the corner top-up
  int added_corners = 0;      // of which from the corner top-up (FeatureTrackerConfig::top_up_below)
  int lost_flow = 0;          // LK found no flow
  int rejected_fb = 0;        // forward-backward check
  int rejected_border = 0;    // left the image (or cannot be undistorted)
  int rejected_ransac = 0;    // fundamental-matrix outliers
  int dropped_crowded = 0;    // inside the min-distance mask of a longer track
  bool ransac_run = false;    // RANSAC needs 8 tracked points
  double inlier_ratio = 1.0;  // RANSAC inliers / points tested (1 when not run)
  bool clahe_applied = false;
  std::vector<int> finished_lengths;  // track lengths of the features that ended at this frame
  std::vector<TrackEnd> finished_causes;  // why each of them ended (parallel to finished_lengths)
  double ms = 0;              // [ms] wall time of track()
};

// Wraps a drover::Image as a cv::Mat without copying (CV_8UC1 or CV_8UC3); throws std::invalid_argument when the
// image is empty or inconsistent.
cv::Mat imageView(const Image& image);

class FeatureTracker {
 public:
  // Throws std::invalid_argument on an invalid config or a null detector.
  FeatureTracker(const CameraModel& camera, std::shared_ptr<KeypointDetector> detector,
                 const FeatureTrackerConfig& config);
  ~FeatureTracker();
  FeatureTracker(const FeatureTracker&) = delete;
  FeatureTracker& operator=(const FeatureTracker&) = delete;

  // One frame: CV_8UC1 or CV_8UC3 of the camera's size, t strictly increasing. Throws std::invalid_argument on a
  // wrong size, type or time.
  TrackingResult track(Time t, const cv::Mat& image);
  const FeatureTrackerConfig& config() const { return config_; }

 private:
  struct Tracks {  // parallel arrays, one entry per live feature
    std::vector<std::uint64_t> ids;
    std::vector<int> lengths;
    std::vector<cv::Point2f> pixels;
    std::vector<Eigen::Vector2d> normalized;
    std::vector<Eigen::Vector2d> velocity;
    std::vector<unsigned char> corner;  // 1 = from the corner top-up (its own LK floor)
    std::size_t size() const { return ids.size(); }
    void keep(const std::vector<unsigned char>& keep_mask);
  };
  cv::Mat preprocess(const cv::Mat& image, TrackingResult& result) const;
  void flow(const cv::Mat& gray, double dt, TrackingResult& result);
  void rejectWithFundamental(const std::vector<Eigen::Vector2d>& previous, TrackingResult& result);
  cv::Mat crowdMask(TrackingResult& result);
  void replenish(const cv::Mat& gray, TrackingResult& result);
  void detect(const cv::Mat& gray, cv::Mat& mask, TrackingResult& result);
  void topUp(const cv::Mat& gray, cv::Mat& mask, TrackingResult& result);
  int cornersBelow() const;  // [tracks] the top-up's threshold: top_up_below, live at least detect_sync_below
  void addDetections(const std::vector<cv::Point2f>& points, cv::Mat& mask, TrackingResult& result,
                     bool corner = false);
  // LK with each track's own floor: the detector's tracks min_eigenvalue, the corners' top_up_min_eigenvalue.
  void flowWithFloors(const cv::Mat& gray, const cv::Size& window, const cv::TermCriteria& criteria,
                      std::vector<cv::Point2f>& current, std::vector<unsigned char>& status);
  bool inside(const cv::Point2f& p) const;
  // Records the tracks keep[i] == 0 drops as finished, for causes[i] (or `cause` for all), and returns keep.
  std::vector<unsigned char> keepFinished(std::vector<unsigned char> keep, const std::vector<TrackEnd>& causes,
                                          TrackingResult& result) const;
  std::vector<unsigned char> keepFinished(std::vector<unsigned char> keep, TrackEnd cause,
                                          TrackingResult& result) const;

  CameraModel camera_;
  std::shared_ptr<KeypointDetector> detector_;
  std::unique_ptr<KeypointDetector> corners_;  // the top-up's Shi-Tomasi (null when cornersBelow() is 0)
  FeatureTrackerConfig config_;
  Tracks tracks_;
  cv::Mat previous_gray_;
  Time previous_t_ = 0;
  bool has_previous_ = false;
  std::uint64_t next_id_ = 0;
  std::optional<Time> last_detection_t_;  // the newest frame a detection ran on (or was started on, asynchronously)
  // Asynchronous detection: the job's frame, the frames since, and the job.
  cv::Mat job_gray_;
  std::vector<cv::Mat> frames_since_job_;
  std::future<Keypoints> job_;
};

}  // namespace drover::visual
