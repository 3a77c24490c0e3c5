// The tracking figures of `drover features track` from hand-made per-frame results (known answers).
#include <gtest/gtest.h>

#include "visual/tracking_summary.hpp"

namespace drover::visual {
namespace {

TrackingResult frame(std::vector<int> live, std::vector<int> finished, std::vector<TrackEnd> causes, int tracked) {
  TrackingResult r;
  for (int length : live) {
    r.features.push_back({0, length, {0, 0}, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()});
  }
  r.finished_lengths = std::move(finished);
  r.finished_causes = std::move(causes);
  r.tracked = tracked;
  return r;
}

TEST(TrackingSummary, LiveAgeAndFinishedTracksByCauseAreMeansOverFramesAndTracks) {
  TrackingSummaryBuilder b;
  b.add(frame({1, 1, 1, 1}, {}, {}, 0));
  b.add(frame({2, 2, 1}, {1}, {TrackEnd::kForwardBackward}, 2));
  b.add(frame({3}, {2, 1, 6}, {TrackEnd::kBorder, TrackEnd::kForwardBackward, TrackEnd::kBorder}, 1));
  const TrackingSummary s = b.summary();
  EXPECT_EQ(s.frames, 3u);
  EXPECT_EQ(s.finished_tracks, 4u);
  EXPECT_DOUBLE_EQ(s.mean_track_length, (1 + 2 + 1 + 6) / 4.0);
  EXPECT_DOUBLE_EQ(s.mean_live_length, (1.0 + 5.0 / 3.0 + 3.0) / 3.0);
  const auto at = [](TrackEnd e) { return static_cast<std::size_t>(e); };
  EXPECT_EQ(s.ended_by[at(TrackEnd::kForwardBackward)], 2u);
  EXPECT_DOUBLE_EQ(s.mean_length_by[at(TrackEnd::kForwardBackward)], 1.0);
  EXPECT_EQ(s.ended_by[at(TrackEnd::kBorder)], 2u);
  EXPECT_DOUBLE_EQ(s.mean_length_by[at(TrackEnd::kBorder)], 4.0);
  EXPECT_EQ(s.ended_by[at(TrackEnd::kRansac)], 0u);
  EXPECT_DOUBLE_EQ(s.mean_length_by[at(TrackEnd::kRansac)], 0.0);
}

}  // namespace
}  // namespace drover::visual
