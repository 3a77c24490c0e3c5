#pragma once
// Figures of a tracking run (drover features track, benchmarks): per-frame counts accumulated into means, and an
// overlay image of the live tracks (drawing only; writing the file is io's job).
#include <array>
#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "visual/feature_tracker.hpp"

namespace drover::visual {

struct TrackingSummary {
  std::size_t frames = 0;
  double mean_features = 0;          // live features after each frame
  double mean_new = 0;               // features added per frame
  // Mean length [frames] of the tracks that ended during the run (lost by the flow, rejected by a check, or
  // dropped by the mask): a track seen in n frames has length n. Tracks still live at the end are left out (their
  // length is cut by the end of the run), so short runs understate long tracks.
  double mean_track_length = 0;
  std::size_t finished_tracks = 0;
  // Mean over frames of the live features' track lengths [frames] (age of what the VIO window sees; not biased
  // toward the many tracks that die young, as mean_track_length is).
  double mean_live_length = 0;
  // The finished tracks by why they ended (index: TrackEnd), with their mean length [frames].
  std::array<std::size_t, kTrackEndCount> ended_by{};
  std::array<double, kTrackEndCount> mean_length_by{};
  double mean_inlier_ratio = 1;      // over frames where RANSAC ran
  double mean_ms = 0, p95_ms = 0, max_ms = 0;  // [ms] per track() call
  // Fraction of frames (after the first) that carried >= 50 features over from the previous frame.
  double fraction_tracked_ge_50 = 0;
};

class TrackingSummaryBuilder {
 public:
  void add(const TrackingResult& result);
  TrackingSummary summary() const;

 private:
  std::vector<double> ms_;
  std::size_t frames_ = 0, finished_ = 0, ransac_frames_ = 0, ge50_ = 0;
  double features_ = 0, new_ = 0, lengths_ = 0, inliers_ = 0, live_lengths_ = 0;
  std::array<std::size_t, kTrackEndCount> ended_by_{};
  std::array<double, kTrackEndCount> lengths_by_{};
};

// A BGR copy of `image` (grey or BGR) with each live feature drawn as a dot coloured by track length (red = new,
// through yellow to green = 20 frames or more) and a line along its velocity over 0.1 s (in pixels of `camera`'s
// focal length), and a caption line with the frame's counts.
cv::Mat drawTracks(const cv::Mat& image, const TrackingResult& result, double focal_px);

}  // namespace drover::visual
