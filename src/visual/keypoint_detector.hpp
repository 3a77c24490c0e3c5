#pragma once
// The detector interface of the visual front end (VINS-Mono's feature_tracker calls goodFeaturesToTrack; Drover
// calls one of these). Implementations: SuperPoint through OpenCV DNN, Shi-Tomasi, ORB. The KLT tracker asks a
// detector for new points inside a mask that excludes the neighbourhoods of live tracks.
//
// Pixel convention (as OpenCV): integer coordinates are pixel centres. A detector is used by one thread at a time
// (the tracker may run it in a worker thread, but never two calls at once).
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace drover::visual {

struct Keypoints {
  std::vector<cv::Point2f> points;  // [px] in the image given to detect(), best first
  std::vector<float> scores;        // detector response, same order (larger = stronger; scale per detector)
  cv::Mat descriptors;              // one row per point (SuperPoint: CV_32F, 256, unit L2; ORB: CV_8U, 32), or empty
};

class KeypointDetector {
 public:
  virtual ~KeypointDetector() = default;
  // image: CV_8UC1, non-empty. mask: empty (everywhere allowed) or CV_8UC1 of the image's size, 0 = no keypoint
  // there. max_count >= 0: at most this many, strongest first. Throws std::invalid_argument on a bad image or mask
  // (naming what was wrong: size, type, emptiness).
  virtual Keypoints detect(const cv::Mat& image, const cv::Mat& mask, int max_count) = 0;
  virtual std::string name() const = 0;  // "superpoint", "shi-tomasi", "orb"
  // True for a detector whose pass costs about a frame's time or more (SuperPoint, ~0.1-0.4 s on these cores): the
  // tracker's detection pacing (FeatureTrackerConfig::detect_interval_s, detect_urgent_below) holds only such a
  // detector. Millisecond detectors (Shi-Tomasi, ORB) detect whenever the tracks need it, as VINS-Mono: a paced
  // Shi-Tomasi starved the lvi-sam preset's VIS on the farm course (20 m APE instead of 0.35 m).
  virtual bool paced() const { return false; }
};

}  // namespace drover::visual
