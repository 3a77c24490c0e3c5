#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "geometry/so3.hpp"
#include "imu/imu_test_paths.hpp"
#include "imu/propagator.hpp"

using namespace drover;
using namespace drover::imu;
using namespace drover::imu::testing;

namespace {

struct StateError {
  double position = 0, rotation = 0, velocity = 0;  // [m], [rad], [m/s]
};

StateError errorOf(const NavState& a, const NavState& b) {
  return {(a.T_world_imu.translation() - b.T_world_imu.translation()).norm(),
          geometry::rotationAngle(a.T_world_imu.linear().transpose() * b.T_world_imu.linear()),
          (a.v_world - b.v_world).norm()};
}

void feed(ImuPropagator& prop, const std::vector<ImuSample>& samples) {
  for (const ImuSample& s : samples) prop.addSample(s);
}

// A straight constant-velocity drive at a fixed tilt: the IMU is constant, so zero-order hold is exact.
sim::SplineTrajectory straightPath() {
  return splineOf([](double t) { return sim::PathSample{0, {2.0 * t, 0.5 * t, 0.1 * t}, 0.3, 0.05, -0.02}; },
                  kSec / 2, 9);
}

// The states of a propagator fed `samples` (reset at the truth at 0.5 s, before the samples are added) at
// every 2.5 ms from 2 s to 3.9 s, i.e. after each bad sample the tests insert at ~1.5 s.
std::vector<NavState> statesAfterDisturbance(const std::vector<ImuSample>& samples, const NavState& start) {
  ImuPropagator prop;
  prop.reset(start, ImuBias{});
  feed(prop, samples);
  std::vector<NavState> out;
  for (Time t = 2 * kSec; t <= 39 * kSec / 10; t += kSec / 400) {
    const auto s = prop.stateAt(t);
    EXPECT_TRUE(s.has_value()) << t;
    if (s) out.push_back(*s);
  }
  return out;
}

// Inserts `bad` before sample index `at` and checks the status, one counter, and that later states are those
// of the clean stream, bit for bit.
void expectRejectedWithoutHarm(const ImuSample& bad, std::size_t at, SampleStatus expected,
                               std::uint64_t ImuStreamStats::*counter) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> clean = sim::simulateImu(path, noiseFree(200.0), 1);
  const NavState start = navStateAt(path, kSec / 2);
  std::vector<ImuSample> dirty(clean.begin(), clean.begin() + static_cast<long>(at));
  ImuPropagator prop;
  prop.reset(start, ImuBias{});
  feed(prop, dirty);
  const SampleStatus status = prop.addSample(bad);
  EXPECT_EQ(status, expected) << toString(status);
  EXPECT_EQ(prop.stats().*counter, 1u);
  feed(prop, std::vector<ImuSample>(clean.begin() + static_cast<long>(at), clean.end()));
  EXPECT_EQ(prop.stats().accepted, clean.size());
  dirty.push_back(bad);
  dirty.insert(dirty.end(), clean.begin() + static_cast<long>(at), clean.end());
  const std::vector<NavState> a = statesAfterDisturbance(clean, start), b = statesAfterDisturbance(dirty, start);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_TRUE(a[k].T_world_imu.isApprox(b[k].T_world_imu, 0.0) && a[k].v_world == b[k].v_world) << k;
  }
}

// Feeds the demanding path at `rate_hz` with a constant bias, resets mid-stream at the truth at ~1.5 s (between
// samples) with that bias, and returns the worst error of stateAt over the next second at 30 kHz query times.
StateError worstErrorOverOneSecond(double rate_hz) {
  const sim::SplineTrajectory path = demandingPath();
  const ImuBias bias{{0.01, -0.02, 0.005}, {0.1, 0.05, -0.2}};
  std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(rate_hz), 1);
  for (ImuSample& s : imu) {
    s.omega_imu += bias.gyro;
    s.acc_imu += bias.acc;
  }
  const long half = static_cast<long>(imu.size() * 5 / 8);  // up to 2.5 s
  ImuPropagator prop;
  EXPECT_FALSE(prop.stateAt(kSec).has_value());
  feed(prop, std::vector<ImuSample>(imu.begin(), imu.begin() + half));
  const Time ti = 3 * kSec / 2 + 123'457;
  prop.reset(navStateAt(path, ti), bias);  // re-propagates the buffered samples
  feed(prop, std::vector<ImuSample>(imu.begin() + half, imu.end()));
  EXPECT_TRUE(prop.initialized());
  EXPECT_EQ(prop.latestTime(), 4 * kSec);
  EXPECT_EQ(errorOf(*prop.stateAt(ti), navStateAt(path, ti)).position, 0.0);
  EXPECT_FALSE(prop.stateAt(ti - 1).has_value());
  EXPECT_TRUE(prop.stateAt(4 * kSec).has_value());
  EXPECT_FALSE(prop.stateAt(4 * kSec + 1).has_value());
  StateError worst;
  for (Time t = ti; t <= ti + kSec; t += 33'333) {  // mostly between samples
    const std::optional<NavState> s = prop.stateAt(t);
    EXPECT_TRUE(s.has_value()) << t;
    if (!s) break;
    const StateError e = errorOf(*s, navStateAt(path, t));
    worst = {std::max(worst.position, e.position), std::max(worst.rotation, e.rotation),
             std::max(worst.velocity, e.velocity)};
  }
  std::printf("[ figures ] stateAt over 1 s at %g Hz: worst position %.3g m, rotation %.3g deg, velocity %.3g m/s\n",
              rate_hz, worst.position, worst.rotation / kDeg, worst.velocity);
  return worst;
}

}  // namespace

TEST(ImuPropagator, StateAtMatchesTheExactTrajectoryAtAndBetweenSampleTimesAfterAReset) {
  // Zero-order hold lags the true state by ~dt/2 times the change of the input since the reset; under the 12 Hz
  // vibration (~28 m/s^2 amplitude) that is up to ~5e-3 m/s of velocity at 5 kHz (~0.02 m/s at 1 kHz). The
  // bounds below hold at 5 kHz, and halving dt halves every error, so what remains is discretisation only.
  const StateError coarse = worstErrorOverOneSecond(2500.0), fine = worstErrorOverOneSecond(5000.0);
  EXPECT_LT(fine.position, 1e-3);
  EXPECT_LT(fine.rotation, 0.01 * kDeg);
  EXPECT_LT(fine.velocity, 5e-3);
  EXPECT_NEAR(coarse.position / fine.position, 2.0, 0.4);
  EXPECT_NEAR(coarse.rotation / fine.rotation, 2.0, 0.4);
  EXPECT_NEAR(coarse.velocity / fine.velocity, 2.0, 0.4);
}

TEST(ImuPropagator, StateAtAgreesWithPreintegrationOfTheSamplesItCovers) {
  const sim::SplineTrajectory path = demandingPath();
  ImuPropagator prop;
  feed(prop, sim::simulateImu(path, noiseFree(200.0), 1));
  const ImuBias bias{{0.003, 0.001, -0.002}, {0.05, 0.0, 0.1}};
  const NavState start = navStateAt(path, kSec + 2'500'000);
  prop.reset(start, bias);
  const Time tj = 2 * kSec + 7'000'000;
  Preintegrator pre(bias, PreintegrationConfig{});
  pre.integrateRange(prop.samplesCovering(start.t, tj), start.t, tj);
  const StateError e = errorOf(pre.predict(start, bias), *prop.stateAt(tj));
  EXPECT_LT(e.position, 1e-9);
  EXPECT_LT(e.rotation, 1e-9);
  EXPECT_LT(e.velocity, 1e-9);
}

TEST(ImuPropagator, ManyIncreasingQueriesInOneSweepAreCheap) {
  const sim::SplineTrajectory path = demandingPath();
  ImuPropagator prop;
  feed(prop, sim::simulateImu(path, noiseFree(400.0), 1));
  prop.reset(navStateAt(path, kSec), ImuBias{});
  const auto begin = std::chrono::steady_clock::now();
  double checksum = 0;
  const int queries = 100'000;  // e.g. 100 sweeps of 1000 columns over 0.1 s each
  for (int q = 0; q < queries; ++q) checksum += prop.stateAt(kSec + q * 25'000LL)->v_world.x();
  const double ns_per_query =
      std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - begin).count() / queries;
  std::printf("[ figures ] stateAt: %.0f ns per query (checksum %.3f)\n", ns_per_query, checksum);
  EXPECT_TRUE(std::isfinite(checksum));
  EXPECT_LT(ns_per_query, 20'000.0);  // generous for a shared, unoptimised machine; ~0.3 us expected
}

TEST(ImuPropagator, NonFiniteSampleIsDroppedCountedAndHarmless) {
  ImuSample bad;
  bad.t = 1'502'500'000;
  bad.acc_imu.x() = std::numeric_limits<double>::quiet_NaN();
  expectRejectedWithoutHarm(bad, 301, SampleStatus::kDroppedNonFinite, &ImuStreamStats::dropped_nonfinite);
}

TEST(ImuPropagator, DuplicateStampIsDroppedAsOutOfOrderAndHarmless) {
  ImuSample bad;
  bad.t = 1'500'000'000;  // the stamp of the sample just before index 301
  bad.acc_imu = Eigen::Vector3d(5, 5, 5);
  expectRejectedWithoutHarm(bad, 301, SampleStatus::kDroppedOutOfOrder, &ImuStreamStats::dropped_out_of_order);
}

TEST(ImuPropagator, BackwardsStampIsDroppedAsOutOfOrderAndHarmless) {
  ImuSample bad;
  bad.t = 1'400'000'000;
  bad.omega_imu = Eigen::Vector3d(1, 2, 3);
  expectRejectedWithoutHarm(bad, 301, SampleStatus::kDroppedOutOfOrder, &ImuStreamStats::dropped_out_of_order);
}

TEST(ImuPropagator, AccelerationSpikeIsDroppedCountedAndHarmless) {
  ImuSample bad;
  bad.t = 1'502'500'000;
  bad.acc_imu = Eigen::Vector3d(0, 120, 120);  // 170 m/s^2 > 150
  expectRejectedWithoutHarm(bad, 301, SampleStatus::kDroppedSpike, &ImuStreamStats::dropped_spike);
}

TEST(ImuPropagator, GyroSpikeIsDroppedCountedAndHarmless) {
  ImuSample bad;
  bad.t = 1'502'500'000;
  bad.acc_imu = Eigen::Vector3d(0, 0, 9.81);
  bad.omega_imu = Eigen::Vector3d(36, 0, 0);  // > 35 rad/s
  expectRejectedWithoutHarm(bad, 301, SampleStatus::kDroppedSpike, &ImuStreamStats::dropped_spike);
}

TEST(ImuPropagator, GapIsReportedCountedAndBridgedByHoldingTheLastSample) {
  const sim::SplineTrajectory path = straightPath();
  std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(200.0), 1);
  ImuPropagator prop;
  prop.reset(navStateAt(path, kSec / 2), ImuBias{});
  for (const ImuSample& s : imu) {
    if (s.t > kSec && s.t < 6 * kSec / 5) continue;  // 0.2 s without samples
    const SampleStatus status = prop.addSample(s);
    EXPECT_EQ(status, s.t == 6 * kSec / 5 ? SampleStatus::kAcceptedAfterGap : SampleStatus::kAccepted) << s.t;
  }
  EXPECT_EQ(prop.stats().gaps, 1u);
  EXPECT_NEAR(prop.stats().largest_gap_s, 0.2, 1e-12);
  EXPECT_EQ(prop.stats().accepted, imu.size() - 39);
  // The measurement is constant on this path, so holding it across the gap is exact.
  for (const Time t : {kSec, 11 * kSec / 10, 6 * kSec / 5, 2 * kSec, 4 * kSec}) {
    const StateError e = errorOf(*prop.stateAt(t), navStateAt(path, t));
    EXPECT_LT(e.position, 1e-9) << t;
    EXPECT_LT(e.rotation, 1e-9) << t;
    EXPECT_LT(e.velocity, 1e-9) << t;
  }
}

TEST(ImuPropagator, BufferKeepsTheNewestFiveSecondsAndForgetsOlderStates) {
  const sim::SplineTrajectory path = straightPath();
  const std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(200.0), 1);  // 0 .. 4 s
  ImuPropagator::Config config;
  config.buffer_s = 2.0;
  ImuPropagator prop(config);
  prop.reset(navStateAt(path, kSec / 2), ImuBias{});
  feed(prop, imu);
  // The sample at the cutoff (4 - 2 = 2 s) is kept: it holds over the cutoff.
  EXPECT_EQ(prop.samples().front().t, 2 * kSec);
  EXPECT_EQ(prop.samples().size(), 401u);
  EXPECT_FALSE(prop.stateAt(kSec).has_value());
  EXPECT_TRUE(prop.stateAt(2 * kSec).has_value());
  EXPECT_LT(errorOf(*prop.stateAt(3 * kSec), navStateAt(path, 3 * kSec)).position, 1e-9);
}

TEST(ImuPropagator, ResetBeforeAnySampleHoldsTheFirstSampleBackToTheState) {
  const sim::SplineTrajectory path = straightPath();
  const std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(200.0), 1);
  ImuPropagator prop;
  prop.reset(navStateAt(path, 0), ImuBias{});
  EXPECT_TRUE(prop.stateAt(0).has_value());
  EXPECT_FALSE(prop.stateAt(1).has_value());  // no sample yet
  feed(prop, std::vector<ImuSample>(imu.begin() + 2, imu.end()));
  EXPECT_LT(errorOf(*prop.stateAt(3 * kSec), navStateAt(path, 3 * kSec)).position, 1e-9);
}

TEST(ImuPropagator, InvalidConfigAndStateAreRejectedNamingTheValue) {
  ImuPropagator::Config c;
  EXPECT_EQ(c.validate(), "");
  c.max_gap_s = 0;
  EXPECT_NE(c.validate().find("max_gap_s"), std::string::npos);
  EXPECT_THROW(ImuPropagator{c}, std::invalid_argument);
  c = ImuPropagator::Config{};
  c.buffer_s = std::nan("");
  EXPECT_NE(c.validate().find("buffer_s"), std::string::npos);
  ImuPropagator prop;
  NavState bad;
  bad.v_world.x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(prop.reset(bad, ImuBias{}), std::invalid_argument);
  EXPECT_FALSE(prop.initialized());
}
