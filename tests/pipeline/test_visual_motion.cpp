// The VIS's motion as the LIS takes it (pipeline::VisualMotion): the pose at a sweep stamp from the VIS's newest
// state before it carried by the IMU, the increment between two stamps against an analytic trajectory, and every
// health gate (warm-up, features, age, reset ID) with its reason.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "geometry/so3.hpp"
#include "pipeline/visual_motion.hpp"
#include "sim/imu_model.hpp"
#include "sim/trajectory.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kSec;
constexpr Time kFrame = kSec / 15;  // 15 Hz camera

// 8 s turning, climbing and accelerating (knots every 0.5 s).
sim::SplineTrajectory turningPath() {
  std::vector<sim::PathSample> samples;
  for (int k = 0; k <= 16; ++k) {
    const double t = 0.5 * k;
    sim::PathSample s;
    s.t = k * kSec / 2;
    s.p_world = {1.5 * t + 0.1 * t * t, 2.0 * std::sin(0.4 * t), 0.2 * std::sin(0.5 * t)};
    s.yaw = 0.3 * t + 0.4 * std::sin(0.6 * t);
    s.pitch = 0.03 * std::sin(0.8 * t);
    s.roll = 0.04 * std::cos(0.7 * t);
    samples.push_back(s);
  }
  return sim::SplineTrajectory(samples);
}

struct MotionCourse {
  sim::SplineTrajectory path = turningPath();
  std::vector<ImuSample> imu;
  imu::PreintegrationConfig preintegration;
  MotionCourse() {
    sim::ImuModelConfig m;  // noiseless and unbiased: the propagation is then exact up to discretisation
    m.gyro_noise_density = m.accel_noise_density = 0;
    m.gyro_bias_random_walk = m.accel_bias_random_walk = 0;
    m.initial_gyro_bias.setZero();
    m.initial_accel_bias.setZero();
    imu = sim::simulateImu(path, m, 3);
  }
  // The propagator as the LIS holds it: every sample up to `until`.
  imu::ImuPropagator propagator(Time until) const {
    imu::ImuPropagator p;
    for (const ImuSample& s : imu)
      if (s.t <= until) p.addSample(s);
    return p;
  }
  VisualState state(Time t, int features = 120, std::uint32_t reset_id = 1, Time initialized_at = 0) const {
    const sim::BodyState b = path.at(t);
    return VisualState{t, b.T_world_body, b.v_world, imu::ImuBias{}, features, reset_id, initialized_at, t, 0,
                       std::nullopt};
  }
};

const MotionCourse& motionCourse() {
  static const MotionCourse c;
  return c;
}

VisualMotion motionWithFrames(Time until, const VisualMotionConfig& config = {}) {
  VisualMotion m(config, motionCourse().preintegration);
  for (Time t = 0; t <= until; t += kFrame) m.add(motionCourse().state(t));
  return m;
}


TEST(VisualWatch, AVisRefusedAtEverySweepForResetAfterIsAskedToResetOnceAndTheCountStartsAgain) {
  VisualWatch watch(1.5);
  const std::string why = "the VIS made no keyframe for 2.0 s while moving at 1.00 m/s";
  std::vector<int> asked;
  for (int k = 0; k <= 40; ++k) {  // 10 Hz sweeps, refused from 0 s to 4 s
    const std::string r = watch.onSweep(k * kSec / 10, false, why);
    if (!r.empty()) {
      asked.push_back(k);
      EXPECT_NE(r.find("1.5 s"), std::string::npos) << r;
      EXPECT_NE(r.find(why), std::string::npos) << r;
    }
  }
  EXPECT_EQ(asked, (std::vector<int>{15, 31}));  // 1.5 s after the first refusal, then 1.5 s after the next one
}

TEST(VisualWatch, AnAcceptedOrAbsentVisBetweenRefusalsStartsTheCountAgainAndZeroNeverAsks) {
  VisualWatch watch(1.5);
  const std::string why = "the VIS's velocity differs from the IMU's prediction by 1.20 m/s";
  for (int k = 0; k < 100; ++k) {
    const bool used = k % 10 == 9;     // accepted once a second
    const bool absent = k % 10 == 4;   // no usable state (a blackout, the warm-up) half-way
    EXPECT_TRUE(watch.onSweep(k * kSec / 10, used, used || absent ? std::string() : why).empty()) << k;
  }
  VisualWatch never(0.0);
  for (int k = 0; k < 100; ++k) EXPECT_TRUE(never.onSweep(k * kSec / 10, false, why).empty()) << k;
}

}  // namespace

TEST(VisualMotion, TheIncrementBetweenTwoSweepStampsIsTheTrueMotionCarriedFromTheFramesBeforeThem) {
  // Sweeps at 10 Hz between 15 Hz frames: each end is up to 67 ms after its frame.
  const Time a = 5 * kSec + 30'000'000, b = a + kSec / 10;
  const VisualMotion m = motionWithFrames(b + 20'000'000);
  std::string why;
  const std::optional<VisualIncrement> inc = m.increment(a, b, motionCourse().propagator(b + 20'000'000), &why);
  ASSERT_TRUE(inc) << why;
  const Eigen::Isometry3d truth = motionCourse().path.at(a).T_world_body.inverse() * motionCourse().path.at(b).T_world_body;
  const double dp = (inc->T_a_b.translation() - truth.translation()).norm();
  const double dr = geometry::logSO3(truth.linear().transpose() * inc->T_a_b.linear()).norm();
  std::printf("increment over %.3f m: |dp| %.2e m, |dtheta| %.2e rad\n", truth.translation().norm(), dp, dr);
  EXPECT_GT(truth.translation().norm(), 0.1);
  EXPECT_LT(dp, 1e-4);
  EXPECT_LT(dr, 1e-5);
  // The sigma is the floor plus the share of the motion, on the translation and the rotation.
  const VisualMotionConfig c;
  const double turned = geometry::logSO3(truth.linear()).norm();
  EXPECT_NEAR(1 / inc->sqrt_information(0, 0), c.sigma_position + c.sigma_position_ratio * truth.translation().norm(),
              1e-5);
  EXPECT_NEAR(1 / inc->sqrt_information(4, 4), c.sigma_rotation + c.sigma_rotation_ratio * turned, 1e-6);
}

TEST(VisualMotion, WithTheWindowCovarianceTheSigmaIsTheFramesCovariancesSummedPlusTheFloor) {
  VisualMotionConfig c;
  c.window_covariance = true;
  VisualMotion m(c, motionCourse().preintegration);
  // Each frame's motion from the one before: 3 mm and 1 mrad per axis (the VIS's window, vio::FrameResult).
  Eigen::Matrix<double, 6, 6> step = Eigen::Matrix<double, 6, 6>::Zero();
  step.diagonal() << Eigen::Vector3d::Constant(9e-6), Eigen::Vector3d::Constant(1e-6);
  for (Time t = 0; t <= 6 * kSec; t += kFrame) {
    VisualState s = motionCourse().state(t);
    if (t > 0) s.relative_covariance = step;
    m.add(s);
  }
  const Time a = 5 * kSec + 30'000'000, b = a + kSec / 10;  // states at 5.000 and 5.067 s (frames 75, 76): one step
  std::string why;
  const std::optional<VisualIncrement> inc = m.increment(a, b, motionCourse().propagator(6 * kSec), &why);
  ASSERT_TRUE(inc) << why;
  const Eigen::Matrix<double, 6, 6> cov = (inc->sqrt_information.transpose() * inc->sqrt_information).inverse();
  // Rotated into a's frame per step; the traces do not depend on that rotation.
  const double position_trace = cov.topLeftCorner(3, 3).trace(), rotation_trace = cov.bottomRightCorner(3, 3).trace();
  EXPECT_NEAR(position_trace, 3 * (9e-6 + c.window_floor_position * c.window_floor_position), 1e-9);
  EXPECT_NEAR(rotation_trace, 3 * (1e-6 + c.window_floor_rotation * c.window_floor_rotation), 1e-10);
  // A frame without a covariance between: the drift model instead.
  VisualMotion gap(c, motionCourse().preintegration);
  for (Time t = 0; t <= 6 * kSec; t += kFrame) {
    VisualState s = motionCourse().state(t);
    if (t > 0 && t != 76 * kFrame) s.relative_covariance = step;  // the frame at 5.067 s has none
    gap.add(s);
  }
  const std::optional<VisualIncrement> drift = gap.increment(a, b, motionCourse().propagator(6 * kSec), &why);
  ASSERT_TRUE(drift) << why;
  EXPECT_NEAR(1 / drift->sqrt_information(5, 5), c.sigma_rotation + c.sigma_rotation_ratio *
              geometry::logSO3(drift->T_a_b.linear()).norm(), 1e-6);
}

TEST(VisualMotion, FewerFeaturesThanAFullFrameWidenTheSigmasAsOneOverTheSquareRoot) {
  const VisualMotionConfig c;  // full_features 80
  VisualMotion full(c, motionCourse().preintegration), quarter(c, motionCourse().preintegration);
  for (Time t = 0; t <= 3 * kSec; t += kFrame) {
    full.add(motionCourse().state(t, 80));
    quarter.add(motionCourse().state(t, 20));
  }
  const imu::ImuPropagator imu = motionCourse().propagator(3 * kSec);
  const auto a = full.increment(2 * kSec, 2 * kSec + kSec / 10, imu, nullptr);
  const auto b = quarter.increment(2 * kSec, 2 * kSec + kSec / 10, imu, nullptr);
  ASSERT_TRUE(a && b);
  EXPECT_NEAR(a->sqrt_information(0, 0) / b->sqrt_information(0, 0), 2.0, 1e-9);
  EXPECT_NEAR(a->sqrt_information(3, 3) / b->sqrt_information(3, 3), 2.0, 1e-9);
}

TEST(VisualMotion, AnUnhealthyVisGivesNoMotionAndSaysWhy) {
  const imu::ImuPropagator imu = motionCourse().propagator(4 * kSec);
  const Time a = 3 * kSec, b = a + kSec / 10;
  std::string why;
  {  // nothing before the first stamp
    VisualMotion m({}, motionCourse().preintegration);
    m.add(motionCourse().state(b + kFrame));
    EXPECT_FALSE(m.increment(a, b, imu, &why));
    EXPECT_NE(why.find("no VIS state"), std::string::npos) << why;
  }
  {  // a camera blackout: the newest state is 0.5 s old
    VisualMotion m({}, motionCourse().preintegration);
    for (Time t = 0; t <= a - kSec / 2; t += kFrame) m.add(motionCourse().state(t));
    EXPECT_FALSE(m.increment(a, b, imu, &why));
    EXPECT_NE(why.find("old"), std::string::npos) << why;
  }
  {  // too few features in the solve
    VisualMotion m({}, motionCourse().preintegration);
    for (Time t = 0; t <= b; t += kFrame) m.add(motionCourse().state(t, 12));
    EXPECT_FALSE(m.increment(a, b, imu, &why));
    EXPECT_NE(why.find("12 features"), std::string::npos) << why;
  }
  {  // initialised 0.5 s before: still warming up
    VisualMotion m({}, motionCourse().preintegration);
    for (Time t = 0; t <= b; t += kFrame) m.add(motionCourse().state(t, 120, 1, a - kSec / 2));
    EXPECT_FALSE(m.increment(a, b, imu, &why));
    EXPECT_NE(why.find("warmup"), std::string::npos) << why;
  }
  {  // a reset between the two stamps (LVI-SAM's reset ID): the two poses are of different windows
    VisualMotion m({}, motionCourse().preintegration);
    for (Time t = 0; t <= b; t += kFrame) m.add(motionCourse().state(t, 120, t < a + kSec / 20 ? 1 : 2, 0));
    EXPECT_FALSE(m.increment(a, b, imu, &why));
    EXPECT_NE(why.find("reset"), std::string::npos) << why;
  }
  {  // and the healthy control
    const VisualMotion m = motionWithFrames(b);
    EXPECT_TRUE(m.increment(a, b, imu, &why)) << why;
  }
}

TEST(VisualMotion, TheStateStreamNumbersTheVisInitialisationsAndSkipsFramesWithoutAnEstimate) {
  VisualStateStream stream;
  vio::FrameResult r;
  r.t = 10;
  EXPECT_FALSE(stream.onFrame(r));  // waiting for initialisation
  r.t = 20, r.initialized = r.just_initialized = true, r.features = 90;
  std::optional<VisualState> s = stream.onFrame(r);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->reset_id, 1u);
  EXPECT_EQ(s->initialized_at, 20);
  EXPECT_EQ(s->features, 90);
  EXPECT_EQ(s->last_keyframe_at, 20);
  r.t = 30, r.just_initialized = false, r.keyframe = true;
  EXPECT_EQ(stream.onFrame(r)->reset_id, 1u);
  r.t = 35, r.keyframe = false;
  EXPECT_EQ(stream.onFrame(r)->last_keyframe_at, 30);
  EXPECT_EQ(stream.onFrame(r)->keyframe_interval, 10);
  r.t = 40, r.initialized = false, r.reset = true;  // a failure cleared the window
  EXPECT_FALSE(stream.onFrame(r));
  r.t = 50, r.initialized = r.just_initialized = true, r.reset = false;
  s = stream.onFrame(r);
  EXPECT_EQ(s->reset_id, 2u);
  EXPECT_EQ(s->initialized_at, 50);
}

// The stall gate asks when the VIS last saw parallax: a keyframe the window made by time alone
// (vio.max_keyframe_interval_s, which keeps a stalled window conditioned) does not count as one.
TEST(VisualMotion, TheStateStreamCountsOnlyKeyframesMadeByParallax) {
  VisualStateStream stream;
  vio::FrameResult r;
  r.t = 20, r.initialized = r.just_initialized = true, r.features = 90;
  ASSERT_TRUE(stream.onFrame(r));
  r.t = 30, r.just_initialized = false, r.keyframe = true;
  EXPECT_EQ(stream.onFrame(r)->last_keyframe_at, 30);
  r.t = 40, r.keyframe_by_time = true;
  const std::optional<VisualState> s = stream.onFrame(r);
  EXPECT_EQ(s->last_keyframe_at, 30);
  EXPECT_EQ(s->keyframe_interval, 10);
  r.t = 45, r.keyframe_by_time = false;
  EXPECT_EQ(stream.onFrame(r)->keyframe_interval, 15);
}

TEST(VisualMotion, InvalidSettingsAreRefusedNamingTheKey) {
  VisualMotionConfig c;
  c.sigma_position = 0;
  EXPECT_NE(c.validate().find("sigma_position"), std::string::npos);
  c = {};
  c.min_features = 100;  // above full_features
  EXPECT_NE(c.validate().find("min_features"), std::string::npos);
  c = {};
  c.max_age = std::nan("");
  EXPECT_NE(c.validate().find("max_age"), std::string::npos);
  c = {};
  c.reset_after = -1;
  EXPECT_NE(c.validate().find("reset_after"), std::string::npos);
  c = {};
  c.max_age = std::nan("");
  EXPECT_THROW(VisualMotion(c, imu::PreintegrationConfig{}), std::invalid_argument);
  EXPECT_TRUE(VisualMotionConfig{}.validate().empty());
}

TEST(VisualMotion, TheIncrementCarriesTheVisGravityAndAccelerometerBiasAtTheLaterStamp) {
  const Time a = 5 * kSec + 30'000'000, b = a + kSec / 10;
  const VisualMotion m = motionWithFrames(b + 20'000'000);
  std::string why;
  const std::optional<VisualIncrement> inc = m.increment(a, b, motionCourse().propagator(b + 20'000'000), &why);
  ASSERT_TRUE(inc) << why;
  const Eigen::Matrix3d R_b = motionCourse().path.at(b).T_world_body.linear();
  const Eigen::Vector3d g_b = R_b.transpose() * Eigen::Vector3d(0, 0, -motionCourse().preintegration.gravity);
  EXPECT_LT((inc->gravity_b - g_b).norm(), 1e-4) << "pitch and roll vary along the path";
  EXPECT_EQ(inc->acc_bias_b, Eigen::Vector3d::Zero());
}

}  // namespace drover::pipeline
