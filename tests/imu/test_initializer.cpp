#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "geometry/so3.hpp"
#include "imu/imu_test_paths.hpp"
#include "imu/initializer.hpp"

using namespace drover;
using namespace drover::imu;
using namespace drover::imu::testing;

namespace {

// 2 s at rest at the given attitude.
sim::SplineTrajectory restingAt(double yaw, double pitch, double roll) {
  return splineOf([=](double) { return sim::PathSample{0, {3, -1, 0.5}, yaw, pitch, roll}; }, kSec / 2, 5);
}

// A noisy unit with a clear gyro bias; the accelerometer bias is zero because at rest it is indistinguishable
// from tilt (0.03 m/s^2 would tilt the estimate by 0.18 deg).
sim::ImuModelConfig noisyUnit(bool orientation) {
  sim::ImuModelConfig c;
  c.initial_gyro_bias = Eigen::Vector3d(0.02, -0.01, 0.015);
  c.initial_accel_bias.setZero();
  c.orientation = orientation;
  return c;
}

}  // namespace

TEST(StaticInitializer, TiltedStaticStartRecoversRollPitchAndGyroBias) {
  const double roll = 5 * kDeg, pitch = -3 * kDeg;
  const sim::ImuModelConfig unit = noisyUnit(false);
  const std::vector<ImuSample> imu = sim::simulateImu(restingAt(0.7, pitch, roll), unit, 3);
  const StaticInitializer::Result r = StaticInitializer().initialize(imu);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_TRUE(r.is_static) << r.reason;
  EXPECT_TRUE(r.reason.empty());
  EXPECT_FALSE(r.used_orientation);
  EXPECT_EQ(r.samples_used, 201u);  // the newest 1 s at 200 Hz, both ends
  const Eigen::Vector3d ypr = sim::eulerFromRotation(r.q_world_imu.toRotationMatrix());
  std::printf("[ figures ] static start: roll error %.4f deg, pitch error %.4f deg, gyro bias error %.2e rad/s\n",
              (ypr[2] - roll) / kDeg, (ypr[1] - pitch) / kDeg, (r.bias.gyro - unit.initial_gyro_bias).norm());
  EXPECT_NEAR(ypr[0], 0.0, 1e-12);  // yaw is unobservable: 0
  EXPECT_NEAR(ypr[1], pitch, 0.05 * kDeg);
  EXPECT_NEAR(ypr[2], roll, 0.05 * kDeg);
  // Standard error of the mean rate per axis: 1.7e-4 * sqrt(200) / sqrt(201) = 1.7e-4 rad/s; allow 5 of them.
  const double sigma_mean = unit.gyro_noise_density * std::sqrt(unit.rate_hz) / std::sqrt(201.0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(r.bias.gyro[i], unit.initial_gyro_bias[i], 5 * sigma_mean) << i;
  EXPECT_EQ(r.bias.acc, Eigen::Vector3d::Zero());
  EXPECT_NEAR(r.gravity_magnitude, 9.81, 0.01);
}

TEST(StaticInitializer, NineAxisOrientationIsUsedWholeIncludingYaw) {
  const double yaw = 1.0, pitch = 0.04, roll = -0.06;
  const std::vector<ImuSample> imu = sim::simulateImu(restingAt(yaw, pitch, roll), noisyUnit(true), 4);
  const StaticInitializer::Result r = StaticInitializer().initialize(imu);
  ASSERT_TRUE(r.ok && r.is_static) << r.reason;
  EXPECT_TRUE(r.used_orientation);
  EXPECT_LT(geometry::rotationAngle(r.q_world_imu.toRotationMatrix().transpose() *
                                    sim::rotationFromEuler(yaw, pitch, roll)),
            1e-9);
  EXPECT_LT(r.tilt_mismatch, 0.05 * kDeg);
  // Without the orientation option the same samples give yaw 0 and gravity's roll/pitch.
  StaticInitializer::Config config;
  config.use_orientation = false;
  const StaticInitializer::Result g = StaticInitializer(config).initialize(imu);
  const Eigen::Vector3d ypr = sim::eulerFromRotation(g.q_world_imu.toRotationMatrix());
  EXPECT_FALSE(g.used_orientation);
  EXPECT_NEAR(ypr[0], 0.0, 1e-12);
  EXPECT_NEAR(ypr[1], pitch, 0.05 * kDeg);
  EXPECT_NEAR(ypr[2], roll, 0.05 * kDeg);
}

TEST(StaticInitializer, MovingStartIsFlaggedNotStaticButStillGivesAnAttitude) {
  const std::vector<ImuSample> imu = sim::simulateImu(demandingPath(), noisyUnit(false), 5);
  const StaticInitializer::Result r = StaticInitializer().initialize(imu);
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_FALSE(r.is_static);
  EXPECT_NE(r.reason.find("std"), std::string::npos) << r.reason;
  EXPECT_EQ(r.bias.gyro, Eigen::Vector3d::Zero());  // no bias is estimated while moving
  EXPECT_TRUE(r.q_world_imu.coeffs().allFinite());
  EXPECT_NEAR(r.q_world_imu.norm(), 1.0, 1e-12);
}

TEST(StaticInitializer, MovingStartTakesTheNineAxisAttitudeOfTheWindowsFirstSampleNotTheWindowsMean) {
  // demandingPath turns ~0.6 rad/s in yaw and pitches through the window: its mean orientation is the attitude of
  // no instant. The start state is placed at the window's first sample, so that sample's attitude is the answer.
  const std::vector<ImuSample> imu = sim::simulateImu(demandingPath(), noisyUnit(true), 8);
  const StaticInitializer::Result r = StaticInitializer().initialize(imu);
  ASSERT_TRUE(r.ok) << r.reason;
  ASSERT_FALSE(r.is_static);
  EXPECT_TRUE(r.used_orientation);
  const Time start = imu.back().t - fromSeconds(StaticInitializer::Config{}.window_s);
  const auto first = std::find_if(imu.begin(), imu.end(), [&](const ImuSample& s) { return s.t >= start; });
  ASSERT_NE(first, imu.end());
  const Eigen::Matrix3d R_first = first->q_world_imu->toRotationMatrix();
  EXPECT_LT(geometry::rotationAngle(r.q_world_imu.toRotationMatrix().transpose() * R_first), 1e-9);
  // The window's mean, what a static start takes, is far from it here: the test can tell the two apart.
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (auto s = first; s != imu.end(); ++s) {
    const Eigen::Vector4d q = s->q_world_imu->coeffs();
    sum += sum.dot(q) < 0 ? -q : q;
  }
  const Eigen::Quaterniond mean(Eigen::Vector4d(sum.normalized()));
  EXPECT_GT(geometry::rotationAngle(mean.toRotationMatrix().transpose() * R_first), 5 * kDeg);
}

TEST(StaticInitializer, SteadyTurnInPlaceIsFlaggedByItsMeanRate) {
  // Constant yaw rate 0.3 rad/s: the rate is steady (small std), but no gyro bias is that large.
  const sim::SplineTrajectory turn =
      splineOf([](double t) { return sim::PathSample{0, {0, 0, 0}, 0.3 * t, 0, 0}; }, kSec / 2, 5);
  const StaticInitializer::Result r = StaticInitializer().initialize(sim::simulateImu(turn, noisyUnit(false), 6));
  ASSERT_TRUE(r.ok) << r.reason;
  EXPECT_FALSE(r.is_static);
  EXPECT_NE(r.reason.find("mean rate"), std::string::npos) << r.reason;
  EXPECT_LT(r.gyro_std, StaticInitializer::Config{}.max_gyro_std);
}

TEST(StaticInitializer, TooShortWindowIsNotOk) {
  std::vector<ImuSample> imu = sim::simulateImu(restingAt(0, 0, 0), noisyUnit(false), 7);
  imu.resize(100);  // 0.5 s < 0.8 of the 1 s window
  const StaticInitializer::Result r = StaticInitializer().initialize(imu);
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.is_static);
  EXPECT_NE(r.reason.find("not enough"), std::string::npos) << r.reason;
  EXPECT_FALSE(StaticInitializer().initialize({}).ok);
}

TEST(StaticInitializer, InvalidConfigIsRejectedNamingTheValue) {
  StaticInitializer::Config c;
  EXPECT_EQ(c.validate(), "");
  c.window_s = -1;
  EXPECT_NE(c.validate().find("window_s"), std::string::npos);
  EXPECT_THROW(StaticInitializer{c}, std::invalid_argument);
  c = StaticInitializer::Config{};
  c.min_coverage = 1.5;
  EXPECT_NE(c.validate().find("min_coverage"), std::string::npos);
}
