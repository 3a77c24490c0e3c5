// Failure detection of the sliding window (VINS-Mono's failureDetection, plus the time offset, the solver and the
// IMU): each trigger clears the window with its reason, and the window re-initialises from the seed afterwards.
#include <gtest/gtest.h>

#include "vio/window_run.hpp"

namespace drover::vio::test {
namespace {

VioConfig failureBase() {
  VioConfig c;
  c.estimate_time_offset = false;
  c.max_features = 60;
  return c;
}

// Runs the scene for `seconds` and returns the first reset (or a result with reset = false).
FrameResult firstReset(const VioConfig& c, double seconds, WindowRun& run, const WindowScene& scene,
                       double camera_delay = 0) {
  SlidingWindowEstimator est(c, imu::PreintegrationConfig{}, scene.T_imu_cam, 460);
  for (double t = 0.05; t < seconds; t += 1.0 / run.camera_hz) {
    const FrameResult r = run.frame(est, t, truthSeeder(scene), camera_delay);
    if (r.reset) return r;
  }
  return {};
}

void expectReset(const FrameResult& r, const std::string& words) {
  EXPECT_TRUE(r.reset);
  EXPECT_NE(r.event.find(words), std::string::npos) << r.event;
  EXPECT_NE(r.event.find("window cleared"), std::string::npos) << r.event;
}

TEST(WindowFailure, HealthyRunNeverResets) {
  const WindowScene scene;
  WindowRun run{scene};
  EXPECT_FALSE(firstReset(failureBase(), 5, run, scene).reset);
}

TEST(WindowFailure, TooFewTrackedFeaturesResets) {
  const WindowScene scene;
  WindowRun run{scene};
  run.edit = [](double t, std::vector<FrameFeature>& fs) {
    if (t > 2 && fs.size() > 4) fs.resize(4);  // a textureless stretch
  };
  expectReset(firstReset(failureBase(), 4, run, scene), "features tracked");
}

TEST(WindowFailure, ImplausibleAccelerometerBiasResets) {
  const WindowScene scene;  // true accelerometer bias 0.054 m/s^2
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_acc_bias = 0.02;
  expectReset(firstReset(c, 8, run, scene), "accelerometer bias");
}

TEST(WindowFailure, ImplausibleGyroBiasResets) {
  WindowScene scene;
  scene.gyro_bias = Eigen::Vector3d(0.03, 0, 0);
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_gyro_bias = 0.01;
  expectReset(firstReset(c, 8, run, scene), "gyro bias");
}

TEST(WindowFailure, PositionJumpResets) {
  const WindowScene scene;  // 1.5 m/s at 15 Hz: 0.1 m between frames
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_jump_m = 0.05;
  expectReset(firstReset(c, 4, run, scene), "position jumped");
}

TEST(WindowFailure, HeightJumpResets) {
  WindowScene scene;
  scene.wave = 3.0;  // up to 2.1 m/s vertically: 0.14 m between frames
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_height_jump_m = 0.05;
  expectReset(firstReset(c, 4, run, scene), "height jumped");
}

TEST(WindowFailure, HeadingJumpResets) {
  const WindowScene scene;  // about 0.5 rad/s: 2 deg between frames
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_turn_deg = 0.5;
  expectReset(firstReset(c, 4, run, scene), "heading jumped");
}

TEST(WindowFailure, ImplausibleSpeedResets) {
  const WindowScene scene;
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.max_speed = 1.0;  // the scene drives 1.5 m/s
  expectReset(firstReset(c, 4, run, scene), "speed");
}

TEST(WindowFailure, TimeOffsetBeyondItsLimitResets) {
  const WindowScene scene;
  WindowRun run{scene};
  VioConfig c = failureBase();
  c.estimate_time_offset = true;
  c.max_time_offset_s = 0.004;
  expectReset(firstReset(c, 10, run, scene, 0.02), "time offset");
}

TEST(WindowFailure, AnImuGapClearsTheWindowAndItReinitialises) {
  const WindowScene scene;
  SlidingWindowEstimator est(failureBase(), imu::PreintegrationConfig{}, scene.T_imu_cam, 460);
  WindowRun run{scene};
  bool reset = false, again = false;
  for (double t = 0.05; t < 5; t += 1.0 / run.camera_hz) {
    if (t > 2 && t < 2.5) {
      run.t_imu = t + 0.6;  // the IMU goes silent past the next frames
      continue;
    }
    const FrameResult r = run.frame(est, t, truthSeeder(scene));
    if (r.reset) {
      reset = true;
      EXPECT_NE(r.event.find("no IMU"), std::string::npos) << r.event;
    }
    again = again || (reset && r.just_initialized);
  }
  EXPECT_TRUE(reset);
  EXPECT_TRUE(again);
}

}  // namespace
}  // namespace drover::vio::test
