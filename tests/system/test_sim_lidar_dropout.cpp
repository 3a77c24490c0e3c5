// A lidar dropout is bridged by the IMU: the smoother joins the sweeps on either side with one IMU factor over the
// gap, so nothing it knew (biases, velocity) is lost. The propagator keeps 20 s of samples for this; the farm's 5 s
// dropout used to fall just outside its 5 s buffer (the sweep after it starts 5.1 s after the one before), and the
// smoother restarted from its loose first-state priors. A dropout longer than the buffer still restarts it, and the
// restart keeps the window's bias covariance (grown by the random walk over the gap).
#include <gtest/gtest.h>

#include <cstdio>
#include <optional>
#include <utility>

#include "support/fused_run.hpp"

namespace drover {
namespace {

constexpr Time kS = 1'000'000'000;

// The straight course (20 s at ~1.2 m/s), the lidar silent 6-12 s, the LIS alone.
test::LiveCourse straightWithDropout() {
  return test::simulateLiveCourse("straight", 0, 1, false, {{sim::FaultKind::kLidarDropout, 6 * kS, 12 * kS}});
}

// The newest biases at or before t.
imu::ImuBias biasAt(const test::FusedRun& r, Time t) {
  imu::ImuBias b;
  for (const auto& [at, bias] : r.biases)
    if (at <= t) b = bias;
  return b;
}

TEST(SimLidarDropout, ASixSecondLidarDropoutIsBridgedByTheImuWithoutASmootherRestart) {
  const test::LiveCourse course = straightWithDropout();
  const test::FusedRun r = test::runFused(course);
  std::printf("straight, lidar silent 6-12 s: %zu smoother restarts, end error %.3f m over %.1f m\n", r.resets.size(),
              r.end_error, r.path);
  ASSERT_GT(r.path, 15.0);
  EXPECT_TRUE(r.resets.empty()) << "restarted at " << (r.resets.empty() ? 0.0 : toSeconds(r.resets.front())) << " s";
  EXPECT_LT(r.end_error, 0.1);  // measured 0.009 m
}

TEST(SimLidarDropout, ADropoutLongerThanTheImuBufferRestartsTheSmootherKeepingWhatItKnewOfTheBiases) {
  const test::LiveCourse course = straightWithDropout();
  const test::FusedRun r = test::runFused(course, 0, true, [](pipeline::OdometryConfig& c) { c.propagator.buffer_s = 2; });
  ASSERT_EQ(r.resets.size(), 1u) << "a 6 s gap with a 2 s IMU buffer must restart the smoother once";
  const Time restart = r.resets.front();
  EXPECT_NEAR(toSeconds(restart), toSeconds(course.truth.front().t) + 12.0, 0.2);
  const imu::ImuBias before = biasAt(r, restart - 1), after = biasAt(r, restart + 3 * kS);
  const double gyro = (after.gyro - before.gyro).norm(), acc = (after.acc - before.acc).norm();
  std::printf("biases across the restart: gyro moved %.2e rad/s, accelerometer %.4f m/s^2 in 3 s\n", gyro, acc);
  // measured 3.7e-5 rad/s and 0.016 m/s^2; restarted from the loose first-state priors 2.1e-4 and 0.034
  EXPECT_LT(gyro, 1e-4);
  EXPECT_LT(acc, 0.025);
}

}  // namespace
}  // namespace drover
