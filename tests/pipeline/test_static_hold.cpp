// pipeline::StaticHold: a static start held at rest until the IMU's integrated specific force or rate (less the
// rest's) says the platform moved.
#include "pipeline/static_hold.hpp"
#include "support/units.hpp"

#include <gtest/gtest.h>

#include <random>

namespace drover::pipeline {
namespace {

using ::drover::test::kMs;
const Eigen::Vector3d kRestForce(0.02, -0.01, 9.81);  // [m/s^2] gravity and an accelerometer bias, IMU frame
const Eigen::Vector3d kRestRate(0.002, -0.001, 0.0015);  // [rad/s] the gyro bias

// 200 Hz samples from t0 (exclusive) to t1 (inclusive) with the simulated IMU's white noise (2e-3 m/s^2/rtHz and
// 1.7e-4 rad/s/rtHz at 200 Hz: 0.028 m/s^2 and 0.0024 rad/s a sample), plus `acc` and `rate` on the rest's.
std::vector<ImuSample> samples(Time t0, Time t1, std::mt19937& rng, const Eigen::Vector3d& acc = Eigen::Vector3d::Zero(),
                               const Eigen::Vector3d& rate = Eigen::Vector3d::Zero()) {
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<ImuSample> out;
  for (Time t = t0 + 5 * kMs; t <= t1; t += 5 * kMs) {
    ImuSample s;
    s.t = t;
    s.acc_imu = kRestForce + acc + 0.028 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    s.omega_imu = kRestRate + rate + 0.0024 * Eigen::Vector3d(n(rng), n(rng), n(rng));
    out.push_back(s);
  }
  return out;
}

StaticHold held() {
  StaticHold h(StaticHoldConfig{0.001, 0.02, 0.01});
  h.begin(0, kRestForce, kRestRate);
  return h;
}

}  // namespace

TEST(StaticHold, AnImuAtRestKeepsTheHoldForFourSecondsOfSweeps) {
  std::mt19937 rng(7);
  StaticHold h = held();
  for (Time t = 0; t < 4000 * kMs; t += 100 * kMs)
    ASSERT_TRUE(h.stillAtRest(samples(t, t + 100 * kMs, rng), t, t + 100 * kMs)) << "ended at " << toSeconds(t) << " s";
  EXPECT_TRUE(h.holding());
  EXPECT_TRUE(h.endReason().empty());
}

TEST(StaticHold, APullAwayAtFourTenthsOfAMetrePerSecondSquaredEndsItWithinTheSweepItBegins) {
  std::mt19937 rng(8);
  StaticHold h = held();
  ASSERT_TRUE(h.stillAtRest(samples(0, 2000 * kMs, rng), 0, 2000 * kMs));
  const Time start = 2000 * kMs;
  EXPECT_FALSE(h.stillAtRest(samples(start, start + 100 * kMs, rng, Eigen::Vector3d(0.4, 0, 0)), start, start + 100 * kMs));
  EXPECT_FALSE(h.holding());
  // 0.02 m/s at 0.4 m/s^2 is 50 ms; the noise moves it by a sample or two.
  EXPECT_GT(h.endedAt(), start + 30 * kMs);
  EXPECT_LT(h.endedAt(), start + 80 * kMs);
  EXPECT_NE(h.endReason().find("velocity change"), std::string::npos) << h.endReason();
  // Over for good: rest again does not bring it back.
  EXPECT_FALSE(h.stillAtRest(samples(start + 100 * kMs, start + 200 * kMs, rng), start + 100 * kMs, start + 200 * kMs));
}

TEST(StaticHold, AGentleAccelerationIsCaughtByItsIntegralNotByAnySingleSweep) {
  // 0.01 m/s^2: a sweep's mean moves by less than its noise (0.028 / sqrt(20) = 0.006 m/s^2 an axis), but the
  // velocity it makes reaches 0.02 m/s after 2 s.
  std::mt19937 rng(9);
  StaticHold h = held();
  Time t = 0;
  while (h.stillAtRest(samples(t, t + 100 * kMs, rng, Eigen::Vector3d(0.01, 0, 0)), t, t + 100 * kMs) && t < 10'000 * kMs)
    t += 100 * kMs;
  EXPECT_FALSE(h.holding());
  EXPECT_GT(h.endedAt(), 1200 * kMs);
  EXPECT_LT(h.endedAt(), 3000 * kMs);
}

TEST(StaticHold, ATurnOnTheSpotEndsItByTheRotation) {
  std::mt19937 rng(10);
  StaticHold h = held();
  EXPECT_FALSE(h.stillAtRest(samples(0, 1000 * kMs, rng, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.1)), 0, 1000 * kMs));
  EXPECT_LT(h.endedAt(), 150 * kMs);  // 0.01 rad at 0.1 rad/s
  EXPECT_NE(h.endReason().find("rotation"), std::string::npos) << h.endReason();
}

TEST(StaticHold, SamplesOutsideTheSweepOrAlreadyCountedAreSkipped) {
  std::mt19937 rng(11);
  StaticHold h = held();
  // A sample long before the sweep holding a jolt must not count, nor the same samples twice.
  std::vector<ImuSample> s = samples(0, 100 * kMs, rng);
  ImuSample jolt = s.front();
  jolt.t = -500 * kMs;
  jolt.acc_imu += Eigen::Vector3d(50, 0, 0);
  s.insert(s.begin(), jolt);
  EXPECT_TRUE(h.stillAtRest(s, 0, 100 * kMs));
  EXPECT_TRUE(h.stillAtRest(s, 0, 100 * kMs));
}

TEST(StaticHold, ASigmaOfZeroNeverHoldsAndTheConfigRefusesNonsense) {
  StaticHold off(StaticHoldConfig{0.0, 0.02, 0.01});
  off.begin(0, kRestForce, kRestRate);
  EXPECT_FALSE(off.holding());
  std::mt19937 rng(12);
  EXPECT_FALSE(off.stillAtRest(samples(0, 100 * kMs, rng), 0, 100 * kMs));
  EXPECT_TRUE(StaticHoldConfig{}.validate().empty());
  EXPECT_FALSE((StaticHoldConfig{-1.0, 0.02, 0.01}).validate().empty());
  EXPECT_FALSE((StaticHoldConfig{0.001, 0.0, 0.01}).validate().empty());
  EXPECT_FALSE((StaticHoldConfig{0.001, 0.02, std::nan("")}).validate().empty());
}

}  // namespace drover::pipeline
