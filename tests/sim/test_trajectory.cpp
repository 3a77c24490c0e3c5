#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "geometry/so3.hpp"
#include "sim/trajectory.hpp"
#include "support/units.hpp"

using namespace drover;
using namespace drover::sim;

namespace {

using ::drover::test::kSec;
using ::drover::test::kPi;

// Uniform samples f(t_rel) at t0 + k * spacing, k = 0..count-1 (t_rel in seconds from t0).
std::vector<PathSample> samplesOf(const std::function<PathSample(double)>& f, Time spacing, int count, Time t0 = 0) {
  std::vector<PathSample> out;
  for (int k = 0; k < count; ++k) {
    PathSample s = f(toSeconds(k * spacing));
    s.t = t0 + k * spacing;
    out.push_back(s);
  }
  return out;
}

// A path that moves and rotates on every axis at once.
PathSample wiggly(double t) {
  PathSample s;
  s.p_world = {2.0 * t + 0.3 * std::sin(1.3 * t), 1.5 * std::sin(0.7 * t), 0.2 * t + 0.1 * std::cos(2.0 * t)};
  s.yaw = 0.3 * t + 0.8 * std::sin(0.5 * t);
  s.pitch = 0.3 * std::sin(1.1 * t);
  s.roll = 0.4 * std::cos(0.9 * t);
  return s;
}

std::vector<Vibration> jolts(Time start, Time end) {
  return {{Vibration::Axis::kZ, 0.01, 5.0, 0.3, start, end, kSec / 2},
          {Vibration::Axis::kPitch, 0.02, 4.0, 1.0, start, end, kSec / 2},
          {Vibration::Axis::kRoll, 0.03, 6.0, -0.5, start, end, kSec / 2}};
}

// A flat, motionless base path: 20 s of samples at 0.5 s spacing, everything zero.
SplineTrajectory still(std::vector<Vibration> vibrations) {
  return SplineTrajectory(samplesOf([](double) { return PathSample{}; }, kSec / 2, 41), std::move(vibrations));
}

Eigen::Vector3d fdVelocity(const SplineTrajectory& tr, Time t, Time d) {
  return (tr.at(t + d).T_world_body.translation() - tr.at(t - d).T_world_body.translation()) / (2 * toSeconds(d));
}

}  // namespace

TEST(SplineTrajectory, PassesThroughEverySampleEvenAtALargeEpoch) {
  const Time t0 = 1'403'715'274'302'142'000;  // EuRoC-like epoch [ns]
  const auto samples = samplesOf(wiggly, kSec / 10, 50, t0);
  const SplineTrajectory tr(samples);
  EXPECT_EQ(tr.startTime(), t0);
  EXPECT_EQ(tr.endTime(), t0 + 49 * kSec / 10);
  for (const PathSample& s : samples) {
    const Eigen::Isometry3d T = tr.pose(s.t);
    EXPECT_LT((T.translation() - s.p_world).norm(), 1e-9) << s.t;
    EXPECT_LT((T.linear() - rotationFromEuler(s.yaw, s.pitch, s.roll)).norm(), 1e-9) << s.t;
  }
}

TEST(SplineTrajectory, PositionVelocityAccelerationAndRateAreContinuousAcrossKnots) {
  const SplineTrajectory tr(samplesOf(wiggly, kSec / 10, 40));
  // Across 2 ns a C2 curve changes by (derivative bound ~ 10) * 2e-9; a C1 spline would jump in a by ~h * jerk.
  for (Time t = kSec / 10; t < tr.endTime(); t += kSec / 10) {
    const BodyState a = tr.at(t - 1), b = tr.at(t + 1);
    EXPECT_LT((a.T_world_body.translation() - b.T_world_body.translation()).norm(), 1e-7) << t;
    EXPECT_LT((a.v_world - b.v_world).norm(), 1e-7) << t;
    EXPECT_LT((a.a_world - b.a_world).norm(), 1e-7) << t;
    EXPECT_LT((a.omega_body - b.omega_body).norm(), 1e-7) << t;
  }
}

TEST(SplineTrajectory, VelocityAndAccelerationEqualCentralDifferencesOfPosition) {
  const SplineTrajectory tr(samplesOf(wiggly, kSec / 10, 60), jolts(kSec, 5 * kSec));
  const Time d = 100'000;  // 0.1 ms
  // Evaluated mid-segment, so t +- d stays within one cubic piece and inside one smooth piece of the envelope.
  // Truncation: v error <= d^2/6 |p'''| ~ 1e-8/6 * 0.01 (2 pi 5)^3 ~ 5e-7; a error <= d^2/12 |p''''| ~ 1e-5;
  // rounding: eps |p| / d ~ 2e-10 for v and eps |p| / d^2 ~ 2e-6 for a.
  for (Time t = kSec / 20; t < tr.endTime(); t += kSec / 10) {
    const BodyState s = tr.at(t);
    const Eigen::Vector3d p0 = s.T_world_body.translation();
    const Eigen::Vector3d pp = tr.at(t + d).T_world_body.translation(), pm = tr.at(t - d).T_world_body.translation();
    const double ds = toSeconds(d);
    EXPECT_LT((s.v_world - fdVelocity(tr, t, d)).norm(), 1e-5) << t;
    EXPECT_LT((s.a_world - (pp - 2.0 * p0 + pm) / (ds * ds)).norm(), 1e-4) << t;
  }
}

TEST(SplineTrajectory, BodyRateEqualsFiniteDifferenceOfRotation) {
  const SplineTrajectory tr(samplesOf(wiggly, kSec / 10, 60), jolts(kSec, 5 * kSec));
  const Time d = 100'000;  // 0.1 ms; central Log(R(t-d)^T R(t+d)) / 2d has error O(d^2 |omega''|) ~ 2e-5
  for (Time t = kSec / 20; t < tr.endTime(); t += kSec / 10) {
    const Eigen::Matrix3d Rm = tr.pose(t - d).linear(), Rp = tr.pose(t + d).linear();
    const Eigen::Vector3d fd = geometry::logSO3(Rm.transpose() * Rp) / (2 * toSeconds(d));
    EXPECT_LT((tr.at(t).omega_body - fd).norm(), 1e-4) << t << " omega " << tr.at(t).omega_body.transpose();
  }
}

TEST(SplineTrajectory, StraightLineAtConstantVelocityIsExact) {
  const Eigen::Vector3d p0(3, -1, 0.5), v(1.2, -0.5, 0.1);
  const SplineTrajectory tr(samplesOf(
      [&](double t) { return PathSample{0, p0 + v * t, 0.3, 0.05, -0.02}; }, kSec / 5, 10, 7 * kSec));
  for (Time t = tr.startTime(); t <= tr.endTime(); t += kSec / 50) {
    const BodyState s = tr.at(t);
    EXPECT_LT((s.T_world_body.translation() - (p0 + v * toSeconds(t - tr.startTime()))).norm(), 1e-12);
    EXPECT_LT((s.v_world - v).norm(), 1e-12);
    EXPECT_LT(s.a_world.norm(), 1e-10);
    EXPECT_LT(s.omega_body.norm(), 1e-12);
  }
}

TEST(SplineTrajectory, NotAKnotEndsReproduceConstantAccelerationUpToTheEnds) {
  // Natural ends would force a = 0 at both ends; not-a-knot reproduces any cubic exactly.
  const Eigen::Vector3d acc(0.3, 0.1, -0.2);
  const SplineTrajectory tr(
      samplesOf([&](double t) { return PathSample{0, 0.5 * acc * t * t, 0.1 * t * t * t, 0, 0}; }, kSec / 5, 8));
  for (Time t : {Time{0}, kSec / 7, tr.endTime() - 1, tr.endTime()}) {
    const BodyState s = tr.at(t);
    const double ts = toSeconds(t);
    EXPECT_LT((s.a_world - acc).norm(), 1e-9) << t;
    EXPECT_LT((s.v_world - acc * ts).norm(), 1e-9) << t;
    EXPECT_NEAR(s.omega_body.z(), 0.3 * ts * ts, 1e-9) << t;
  }
}

TEST(SplineTrajectory, ConstantRateCircleGivesCentripetalAccelerationAndYawRate) {
  const double r = 4.0, speed = 1.5, h = 0.2;  // [m], [m/s], knot spacing [s]
  const auto circle = [&](double t) {
    const double th = speed * t / r;
    return PathSample{0, {r * std::cos(th), r * std::sin(th), 1.0}, th + kPi / 2, 0, 0};
  };
  const SplineTrajectory tr(samplesOf(circle, fromSeconds(h), 41));
  // Cubic spline interpolation error |e^(k)| <= C_k h^(4-k) |f''''|, C = 5/384, 1/24, 3/8 (Hall & Meyer 1976,
  // complete spline), |f''''| = speed^4 / r^3 on the circle. The not-a-knot ends are worse: within 3 knots of
  // them allow 5x (measured: up to 4.3x in v, 2.2x in p, 1.9x in a; further in, at most 0.24x).
  const double f4 = std::pow(speed, 4) / std::pow(r, 3);
  const Eigen::Vector3d bound(5.0 / 384 * std::pow(h, 4) * f4, 1.0 / 24 * std::pow(h, 3) * f4, 3.0 / 8 * h * h * f4);
  for (Time t = 0; t <= tr.endTime(); t += kSec / 100) {
    const bool inside = t >= fromSeconds(3 * h) && t <= tr.endTime() - fromSeconds(3 * h);
    const Eigen::Vector3d b = inside ? bound : Eigen::Vector3d(5 * bound);
    const BodyState s = tr.at(t);
    const double th = speed * toSeconds(t) / r;
    const Eigen::Vector3d radial(std::cos(th), std::sin(th), 0), tangent(-std::sin(th), std::cos(th), 0);
    EXPECT_LT((s.T_world_body.translation() - (r * radial + Eigen::Vector3d::UnitZ())).norm(), b[0]) << t;
    EXPECT_LT((s.v_world - speed * tangent).norm(), b[1]) << t;
    EXPECT_LT((s.a_world + speed * speed / r * radial).norm(), b[2]) << t;
    EXPECT_NEAR(s.a_world.norm(), speed * speed / r, b[2]) << t;
    EXPECT_LT((s.omega_body - Eigen::Vector3d(0, 0, speed / r)).norm(), 1e-12) << t;  // yaw is linear: exact
  }
  EXPECT_NEAR(tr.pathLength(), speed * toSeconds(tr.endTime()), 1e-6);
}

TEST(SplineTrajectory, VibrationHasItsAmplitudeAtItsPeaksAndFrequency) {
  const double amp = 0.01, f = 4.0, phase = 0.3;
  const Time start = 2 * kSec, end = 12 * kSec;
  const SplineTrajectory tr = still({{Vibration::Axis::kZ, amp, f, phase, start, end, kSec / 2}});
  const double w = 2 * kPi * f;
  int peaks = 0;
  for (int k = 0; k < 100; ++k) {
    const double tau = (kPi / 2 + 2 * kPi * k - phase) / w;  // sin(w tau + phase) = 1
    const Time t = start + fromSeconds(tau);
    if (t < start + kSec / 2 || t > end - kSec / 2) continue;  // full envelope only
    const BodyState s = tr.at(t);
    EXPECT_NEAR(s.T_world_body.translation().z(), amp, 1e-12);
    EXPECT_NEAR(s.v_world.z(), 0.0, 1e-8);
    EXPECT_NEAR(s.a_world.z(), -amp * w * w, 1e-6);
    EXPECT_NEAR(tr.at(t + fromSeconds(0.5 / f)).T_world_body.translation().z(), -amp, 1e-12);  // half a period
    ++peaks;
  }
  EXPECT_EQ(peaks, 36);  // 4 Hz over the 9 s of full envelope
}

TEST(SplineTrajectory, VibrationEnvelopeIsZeroOutsideItsSpanAndHalfInTheMiddleOfARamp) {
  const Time start = 2 * kSec, end = 12 * kSec, ramp = kSec / 2;
  const SplineTrajectory tr = still({{Vibration::Axis::kRoll, 0.05, 3.0, 0.7, start, end, ramp}});
  for (Time t : {Time{0}, start - 1, start, end, end + 1, 20 * kSec}) {
    const BodyState s = tr.at(t);
    EXPECT_TRUE(s.T_world_body.linear().isIdentity(0.0)) << t;
    EXPECT_EQ(s.omega_body.norm(), 0.0) << t;
  }
  // smoothstep(1/2) = 1/2.
  const Eigen::Vector3d e = eulerFromRotation(tr.pose(start + ramp / 2).linear());
  EXPECT_NEAR(e[2], 0.5 * 0.05 * std::sin(2 * kPi * 3.0 * toSeconds(ramp / 2) + 0.7), 1e-12);
}

TEST(SplineTrajectory, VibrationIsC2AtTheRampEnds) {
  const Time start = 2 * kSec, end = 12 * kSec, ramp = kSec / 2;
  // Phases chosen so the sine is far from zero at every ramp end (a C1 envelope would then jump in a).
  const SplineTrajectory tr = still({{Vibration::Axis::kZ, 0.02, 2.0, kPi / 2, start, end, ramp},
                                     {Vibration::Axis::kPitch, 0.02, 2.0, kPi / 2, start, end, ramp},
                                     {Vibration::Axis::kRoll, 0.02, 2.0, kPi / 2, start, end, ramp}});
  const Time d = 10'000;  // 10 us one-sided slopes of omega: equal when omega' is continuous
  for (Time t : {start, start + ramp, end - ramp, end}) {
    const BodyState a = tr.at(t - 1), b = tr.at(t + 1);
    EXPECT_LT((a.T_world_body.translation() - b.T_world_body.translation()).norm(), 1e-9) << t;
    EXPECT_LT((a.v_world - b.v_world).norm(), 1e-8) << t;
    EXPECT_LT((a.a_world - b.a_world).norm(), 1e-6) << t;
    EXPECT_LT((a.omega_body - b.omega_body).norm(), 1e-8) << t;
    const Eigen::Vector3d left = (tr.at(t).omega_body - tr.at(t - d).omega_body) / toSeconds(d);
    const Eigen::Vector3d right = (tr.at(t + d).omega_body - tr.at(t).omega_body) / toSeconds(d);
    EXPECT_LT((left - right).norm(), 1e-2) << t;  // ~ d |omega'''|; a C1 envelope jumps by 6 A / ramp^2 ~ 0.5
  }
}

TEST(SplineTrajectory, AtOutsideTheSpanThrows) {
  const SplineTrajectory tr(samplesOf(wiggly, kSec / 10, 10, kSec));
  EXPECT_NO_THROW(tr.at(tr.startTime()));
  EXPECT_NO_THROW(tr.at(tr.endTime()));
  EXPECT_THROW(tr.at(tr.startTime() - 1), std::out_of_range);
  EXPECT_THROW(tr.at(tr.endTime() + 1), std::out_of_range);
}

TEST(SplineTrajectory, TooFewNonUniformOrNonFiniteSamplesOrBadVibrationsThrow) {
  auto samples = samplesOf(wiggly, kSec / 10, 10);
  EXPECT_THROW(SplineTrajectory(std::vector<PathSample>(samples.begin(), samples.begin() + 3)), std::invalid_argument);
  EXPECT_NO_THROW(SplineTrajectory(std::vector<PathSample>(samples.begin(), samples.begin() + 4)));
  auto jitter = samples;
  jitter[5].t += 1;
  EXPECT_THROW(SplineTrajectory{jitter}, std::invalid_argument);
  auto same = samples;
  for (auto& s : same) s.t = 0;
  EXPECT_THROW(SplineTrajectory{same}, std::invalid_argument);
  auto nan = samples;
  nan[2].pitch = std::nan("");
  EXPECT_THROW(SplineTrajectory{nan}, std::invalid_argument);
  EXPECT_THROW(SplineTrajectory(samples, {{Vibration::Axis::kZ, 0.1, 1.0, 0.0, 0, kSec, 0}}), std::invalid_argument);
  EXPECT_THROW(SplineTrajectory(samples, {{Vibration::Axis::kZ, 0.1, 1.0, 0.0, kSec, kSec, 1}}), std::invalid_argument);
}

TEST(SplineTrajectory, SampleCoversTheSpanOnTheRateGridIncludingBothEnds) {
  const SplineTrajectory tr(samplesOf(wiggly, kSec / 10, 21, 5 * kSec));  // 2 s
  const Trajectory at10 = tr.sample(10.0);
  ASSERT_EQ(at10.size(), 21u);
  EXPECT_EQ(at10.front().t, tr.startTime());
  EXPECT_EQ(at10.back().t, tr.endTime());
  EXPECT_TRUE(at10[7].T_world_body.isApprox(tr.pose(tr.startTime() + 7 * kSec / 10), 1e-15));
  const Trajectory at3 = tr.sample(3.0);
  ASSERT_EQ(at3.size(), 7u);
  EXPECT_EQ(at3[1].t - tr.startTime(), 333'333'333);
  EXPECT_EQ(at3[2].t - tr.startTime(), 666'666'667);
  EXPECT_EQ(at3.back().t, tr.endTime());
  EXPECT_EQ(tr.sample(4.0 / 3.0).size(), 3u);  // 0, 0.75, 1.5 s: the end is not on that grid
  EXPECT_THROW(tr.sample(0.0), std::invalid_argument);
}

TEST(SplineTrajectory, PathLengthOfAStraightLineIsSpeedTimesDuration) {
  const SplineTrajectory tr(samplesOf([](double t) { return PathSample{0, {0.6 * t, 0.8 * t, 0}, 0, 0, 0}; },
                                      kSec / 3, 10));  // ~3 s at 1 m/s; the last 100 Hz step is shorter
  EXPECT_NEAR(tr.pathLength(), toSeconds(tr.endTime()), 1e-12);
}

TEST(SplineTrajectory, ResampleInterpolatesKeyframesLinearlyAndUnwrapsYaw) {
  const std::vector<PathSample> keys = {{0, {0, 0, 0}, 3.0, 0.0, 0.1},
                                        {fromSeconds(0.3), {3, 0, 0}, -3.0, 0.3, 0.1},
                                        {fromSeconds(1.0), {3, 7, 0}, -3.0, 0.3, 0.1},
                                        {fromSeconds(1.1), {0, 0, 9}, -3.0, 0.3, 0.1}};
  const auto grid = SplineTrajectory::resample(keys, fromSeconds(0.15));
  ASSERT_EQ(grid.size(), 8u);  // 0 .. 1.05 s
  EXPECT_EQ(grid[7].t, fromSeconds(1.05));
  EXPECT_LT((grid[1].p_world - Eigen::Vector3d(1.5, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(grid[1].yaw, kPi, 1e-12);  // halfway from 3 to 2 pi - 3 (not through 0)
  EXPECT_NEAR(grid[1].pitch, 0.15, 1e-12);
  EXPECT_LT((grid[4].p_world - Eigen::Vector3d(3, 3, 0)).norm(), 1e-12);  // 0.6 s
  EXPECT_LT((grid[7].p_world - Eigen::Vector3d(1.5, 3.5, 4.5)).norm(), 1e-12);
  EXPECT_THROW(SplineTrajectory::resample(keys, 0), std::invalid_argument);
  EXPECT_THROW(SplineTrajectory::resample({keys[1], keys[0]}, kSec), std::invalid_argument);
}

TEST(SplineTrajectory, EulerAnglesRoundTripAndFromPosesUnwrapsYaw) {
  Trajectory poses;
  for (int k = 0; k < 40; ++k) {
    const double yaw = 0.35 * k, pitch = 0.4 * std::sin(k), roll = -0.3 * std::cos(k);  // yaw turns twice round
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotationFromEuler(yaw, pitch, roll);
    // Compare with the composition of elementary rotations.
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX())).toRotationMatrix();
    EXPECT_LT((T.linear() - R).norm(), 1e-14);
    T.translation() = Eigen::Vector3d(k, 0, 0);
    poses.push_back({k * kSec / 10, T});
  }
  const auto samples = SplineTrajectory::fromPoses(poses);
  ASSERT_EQ(samples.size(), poses.size());
  for (int k = 0; k < 40; ++k) {
    EXPECT_NEAR(samples[k].yaw, 0.35 * k, 1e-12);
    EXPECT_NEAR(samples[k].pitch, 0.4 * std::sin(k), 1e-12);
    EXPECT_NEAR(samples[k].roll, -0.3 * std::cos(k), 1e-12);
    EXPECT_EQ(samples[k].t, k * kSec / 10);
  }
}
