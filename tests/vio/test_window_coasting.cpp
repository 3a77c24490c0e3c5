// Coasting (no LIS): a window that loses its tracks for a while (the dark, a covered lens, a blank wall) goes on on
// the IMU and its marginal prior instead of being cleared, and continues when the tracks come back. The scene: the
// window is seeded from the truth (a LIS that then stops), every feature vanishes from 3 to 5 s, and from 3 s on no
// seed is given, so what happens after 3 s is the VIS's own business.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "vio/window_run.hpp"

namespace drover::vio::test {
namespace {

constexpr double kDarkFrom = 3.0, kDarkTo = 5.0, kEnd = 9.0;  // [s]

VioConfig base() {
  VioConfig c;
  c.estimate_time_offset = false;
  c.max_features = 80;
  return c;
}

struct Outcome {
  int resets = 0, coasted = 0;
  std::optional<FrameResult> first_reset, first_coast;
  FrameResult last;
  double worst_position_after_dark = 0;  // [m] against the truth, from the end of the dark on
};

// `kept`: features still seen in the dark (the first of each frame's list: the same ones while they stay in view).
Outcome runDark(const VioConfig& c, const Seeder& after_dark_start = nullptr, std::size_t kept = 0,
                std::vector<FrameResult>* dark = nullptr) {
  const WindowScene scene;
  SlidingWindowEstimator est(c, imu::PreintegrationConfig{}, scene.T_imu_cam, 460);
  WindowRun run{scene};
  run.edit = [kept](double t, std::vector<FrameFeature>& f) {
    if (t >= kDarkFrom && t < kDarkTo) f.resize(std::min(kept, f.size()));
  };
  const Seeder truth = truthSeeder(scene);
  Outcome out;
  for (double t = 0.05; t < kEnd; t += 1.0 / run.camera_hz) {
    const FrameResult r = run.frame(est, t, t < kDarkFrom ? truth : after_dark_start);
    if (dark && t >= kDarkFrom && t < kDarkTo) dark->push_back(r);
    if (r.reset && !out.first_reset) out.first_reset = r;
    if (r.coasting && !out.first_coast) out.first_coast = r;
    out.resets += r.reset ? 1 : 0;
    out.coasted += r.coasting ? 1 : 0;
    if (t >= kDarkTo && r.initialized) {
      const double e = (r.T_world_imu.translation() - scene.truth(toSeconds(r.t)).T_world_imu.translation()).norm();
      out.worst_position_after_dark = std::max(out.worst_position_after_dark, e);
    }
    out.last = r;
  }
  return out;
}

TEST(WindowCoasting, AloneTheWindowCoastsThroughTwoDarkSecondsAndGoesOnWhenTheTracksReturn) {
  const Outcome o = runDark(base());
  EXPECT_EQ(o.resets, 0) << o.first_reset->event;
  EXPECT_GE(o.coasted, 29);  // the dark's 30 frames, less the first lit one (its features are new to the window)
  EXPECT_LE(o.coasted, 32);
  ASSERT_TRUE(o.first_coast.has_value());
  EXPECT_TRUE(o.first_coast->initialized);
  EXPECT_NE(o.first_coast->event.find("coasting on the IMU"), std::string::npos) << o.first_coast->event;
  ASSERT_TRUE(o.last.initialized);
  EXPECT_FALSE(o.last.coasting);
  // Seeded from the truth before the dark, so the truth's world. Dead reckoning for 2 s on a bias the window has had
  // 3 s to find (the scene's is 0.054 m/s^2): at most 1/2 0.054 (2 s)^2 = 0.11 m, then 4 s of VIO.
  EXPECT_LT(o.worst_position_after_dark, 0.15) << "m";
  const WindowScene scene;
  EXPECT_LT((o.last.v_world - scene.truth(toSeconds(o.last.t)).v_world).norm(), 0.05) << "m/s";
}

// With coasting off the first dark frame clears the window; alone at constant speed it could not start again (here
// the alignment is made unable to determine the scale: a robot driving at constant speed).
TEST(WindowCoasting, WithoutItTheFirstDarkFrameClearsTheWindowForGood) {
  VioConfig c = base();
  c.coast_max_s = 0;
  c.init_max_scale_rel_sigma = 1e-9;
  const Outcome o = runDark(c);
  EXPECT_EQ(o.resets, 1);
  EXPECT_EQ(o.coasted, 0);
  ASSERT_TRUE(o.first_reset.has_value());
  EXPECT_NEAR(toSeconds(o.first_reset->t), kDarkFrom, 0.1);
  EXPECT_FALSE(o.last.initialized) << o.last.event;
}

TEST(WindowCoasting, ADarkLongerThanCoastMaxSecondsClearsTheWindowAndSaysHowLong) {
  VioConfig c = base();
  c.coast_max_s = 1.0;  // the dark lasts 2 s
  const Outcome o = runDark(c);
  ASSERT_TRUE(o.first_reset.has_value());
  EXPECT_NEAR(toSeconds(o.first_reset->t), kDarkFrom + 1.0, 0.15);
  EXPECT_NE(o.first_reset->event.find("features tracked into the frame (< 8) for 1."), std::string::npos)
      << o.first_reset->event;
  EXPECT_GE(o.coasted, 13);
}

TEST(WindowCoasting, WithALisToSeedItTheWindowIsClearedAtOnceAndStartsAgainFromTheLis) {
  const WindowScene scene;
  const Outcome o = runDark(base(), truthSeeder(scene));
  EXPECT_EQ(o.coasted, 0);
  ASSERT_TRUE(o.first_reset.has_value());
  EXPECT_NEAR(toSeconds(o.first_reset->t), kDarkFrom, 0.1);
  ASSERT_TRUE(o.last.initialized) << o.last.event;
  EXPECT_LT(o.worst_position_after_dark, 0.05) << "m";
}

// With a LIS, the failure check clears a window whose newest frame tracks fewer than min_tracked (8) features, so
// the window does not initialise on fewer: in a dark where 5 features stay in view it waits, saying why, instead of
// initialising from the LIS and clearing again at the next frame (the farm's white walls: every 0.8 s).
TEST(WindowCoasting, WithALisTheWindowWaitsForEnoughTracksInsteadOfInitialisingAndClearingAgain) {
  const WindowScene scene;
  std::vector<FrameResult> dark;
  const Outcome o = runDark(base(), truthSeeder(scene), 5, &dark);
  EXPECT_EQ(o.resets, 1) << "only the dark's first frame";
  ASSERT_FALSE(dark.empty());
  EXPECT_TRUE(std::none_of(dark.begin(), dark.end(), [](const FrameResult& r) { return r.initialized; }));
  EXPECT_EQ(dark.back().tracked, 5);
  EXPECT_EQ(dark.back().event, "not initialised: only 5 features tracked into the newest frame (< min_tracked 8)");
  ASSERT_TRUE(o.last.initialized) << o.last.event;
  EXPECT_LT(o.worst_position_after_dark, 0.05) << "m";
}

}  // namespace
}  // namespace drover::vio::test
