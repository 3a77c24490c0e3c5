#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "geometry/so3.hpp"
#include "sim/imu_model.hpp"
#include "support/units.hpp"

using namespace drover;
using namespace drover::sim;

namespace {

using ::drover::test::kSec;

SplineTrajectory splineOf(const std::function<PathSample(double)>& f, Time spacing, int count,
                          std::vector<Vibration> vibrations = {}) {
  std::vector<PathSample> samples;
  for (int k = 0; k < count; ++k) {
    PathSample s = f(toSeconds(k * spacing));
    s.t = k * spacing;
    samples.push_back(s);
  }
  return SplineTrajectory(samples, std::move(vibrations));
}

// Turning, climbing and jolting at once: 4 s, with vibrations on z (12 Hz), pitch (9 Hz) and roll (7 Hz).
SplineTrajectory demandingPath() {
  const auto f = [](double t) {
    PathSample s;
    s.p_world = {1.2 * t, 2.0 * std::sin(0.5 * t), 0.15 * t + 0.05 * std::sin(1.5 * t)};
    s.yaw = 0.6 * t + 0.3 * std::sin(t);
    s.pitch = -0.1 + 0.05 * std::sin(0.7 * t);
    s.roll = 0.08 * std::cos(1.3 * t);
    return s;
  };
  return splineOf(f, kSec / 10, 41,
                  {{Vibration::Axis::kZ, 0.005, 12.0, 0.2, kSec / 2, 7 * kSec / 2, 3 * kSec / 10},
                   {Vibration::Axis::kPitch, 0.01, 9.0, 1.1, kSec / 2, 7 * kSec / 2, 3 * kSec / 10},
                   {Vibration::Axis::kRoll, 0.015, 7.0, -0.4, kSec / 2, 7 * kSec / 2, 3 * kSec / 10}});
}

// A gentle 100 s wander for the noise statistics.
SplineTrajectory longPath() {
  return splineOf(
      [](double t) {
        return PathSample{0, {0.5 * t, std::sin(0.1 * t), 0.0}, 0.2 * std::sin(0.05 * t), 0.02, -0.01};
      },
      kSec / 2, 201);
}

ImuModelConfig noiseFree(double rate_hz) {
  ImuModelConfig c;
  c.rate_hz = rate_hz;
  c.noise = false;
  return c;
}

struct NavState {
  Eigen::Quaterniond q;
  Eigen::Vector3d v, p;
};

// d/dt of (q_world_imu, v_world, p_world) given the body rate and specific force (g = (0, 0, -9.81)).
NavState derivative(const NavState& x, const Eigen::Vector3d& omega, const Eigen::Vector3d& acc) {
  const Eigen::Quaterniond qn = x.q.normalized();
  NavState d;
  d.q.coeffs() = 0.5 * (x.q * Eigen::Quaterniond(0, omega.x(), omega.y(), omega.z())).coeffs();
  d.v = qn * acc + Eigen::Vector3d(0, 0, -9.81);
  d.p = x.v;
  return d;
}

NavState axpy(const NavState& x, double h, const NavState& d) {
  NavState y;
  y.q.coeffs() = x.q.coeffs() + h * d.q.coeffs();
  y.v = x.v + h * d.v;
  y.p = x.p + h * d.p;
  return y;
}

// Classical RK4 with step 2 dt: samples k, k+1, k+2 give the inputs at the start, middle and end of a step.
NavState integrateRk4(NavState x, const std::vector<ImuSample>& imu, std::size_t first, std::size_t steps) {
  for (std::size_t s = 0; s < steps; ++s) {
    const ImuSample &a = imu[first + 2 * s], &m = imu[first + 2 * s + 1], &b = imu[first + 2 * s + 2];
    const double h = toSeconds(b.t - a.t);
    const NavState k1 = derivative(x, a.omega_imu, a.acc_imu);
    const NavState k2 = derivative(axpy(x, h / 2, k1), m.omega_imu, m.acc_imu);
    const NavState k3 = derivative(axpy(x, h / 2, k2), m.omega_imu, m.acc_imu);
    const NavState k4 = derivative(axpy(x, h, k3), b.omega_imu, b.acc_imu);
    x.q.coeffs() += h / 6 * (k1.q.coeffs() + 2 * k2.q.coeffs() + 2 * k3.q.coeffs() + k4.q.coeffs());
    x.q.normalize();
    x.v += h / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v);
    x.p += h / 6 * (k1.p + 2 * k2.p + 2 * k3.p + k4.p);
  }
  return x;
}

// Per-channel (6 = gyro xyz, accel xyz) differences measured - truth.
using Vector6d = Eigen::Matrix<double, 6, 1>;
std::vector<Vector6d> errors(const std::vector<ImuSample>& meas, const std::vector<ImuSample>& truth) {
  std::vector<Vector6d> e(meas.size());
  for (std::size_t k = 0; k < meas.size(); ++k) {
    e[k] << meas[k].omega_imu - truth[k].omega_imu, meas[k].acc_imu - truth[k].acc_imu;
  }
  return e;
}

}  // namespace

TEST(ImuModel, NoiseFreeImuIntegratesToTheTruePoseChangeOnATurningClimbingJoltingPath) {
  const SplineTrajectory tr = demandingPath();
  // At the default 200 Hz RK4 (4th order, 10 ms steps) leaves ~4e-5 m and ~1e-5 deg here (measured: 7e-4 m at
  // 100 Hz, 3e-6 m at 400 Hz); a wrong frame, sign or rate formula in the IMU model gives centimetres or more.
  const std::vector<ImuSample> imu = simulateImu(tr, noiseFree(200.0), 1);
  const std::size_t first = 300;  // t = 1.5 s, inside the vibrations' full envelope
  ASSERT_EQ(imu[first].t, 3 * kSec / 2);
  const BodyState s0 = tr.at(imu[first].t);
  NavState x{Eigen::Quaterniond(s0.T_world_body.linear()), s0.v_world, s0.T_world_body.translation()};
  x = integrateRk4(x, imu, first, 100);  // 1 s
  const BodyState s1 = tr.at(imu[first + 200].t);
  EXPECT_LT((x.p - s1.T_world_body.translation()).norm(), 1e-3);
  EXPECT_LT(geometry::rotationAngle(s1.T_world_body.linear().transpose() * x.q.toRotationMatrix()),
            0.01 * std::numbers::pi / 180);
  EXPECT_LT((x.v - s1.v_world).norm(), 1e-3);
  // Sanity: the path really moves, turns and jolts over that second.
  EXPECT_GT((s1.T_world_body.translation() - s0.T_world_body.translation()).norm(), 1.0);
  EXPECT_GT(geometry::rotationAngle(s0.T_world_body.linear().transpose() * s1.T_world_body.linear()), 0.4);
}

TEST(ImuModel, NoiseFreeImuAtRestMeasuresGravityInTheTiltedFrameAndZeroRate) {
  const double yaw = 1.0, pitch = 0.2, roll = -0.1;
  const SplineTrajectory tr = splineOf([&](double) { return PathSample{0, {1, 2, 3}, yaw, pitch, roll}; }, kSec / 2, 5);
  const Eigen::Matrix3d R = rotationFromEuler(yaw, pitch, roll);
  const auto imu = simulateImu(tr, noiseFree(200.0), 7);
  ASSERT_EQ(imu.size(), 401u);
  for (const ImuSample& m : imu) {
    EXPECT_LT((m.acc_imu - R.transpose() * Eigen::Vector3d(0, 0, 9.81)).norm(), 1e-12);
    EXPECT_LT(m.omega_imu.norm(), 1e-12);
    ASSERT_TRUE(m.q_world_imu.has_value());
    EXPECT_LT((m.q_world_imu->toRotationMatrix() - R).norm(), 1e-12);
  }
  ImuModelConfig no_q = noiseFree(200.0);
  no_q.orientation = false;
  EXPECT_FALSE(simulateImu(tr, no_q, 7).front().q_world_imu.has_value());
}

TEST(ImuModel, SampleTimesAreStartPlusRoundedMultiplesOfThePeriod) {
  const SplineTrajectory tr = splineOf([](double) { return PathSample{}; }, kSec / 4, 5);  // 1 s
  const auto imu = simulateImu(tr, noiseFree(300.0), 1);
  ASSERT_EQ(imu.size(), 301u);  // both ends
  for (std::size_t k = 0; k < imu.size(); ++k) EXPECT_EQ(imu[k].t, std::llround(k * 1e9 / 300.0));
  EXPECT_EQ(simulateImu(tr, noiseFree(1.5), 1).size(), 2u);  // 0 and 0.667 s; the end is off the grid
}

TEST(ImuModel, WhiteNoiseStandardDeviationIsDensityOverRootDt) {
  const SplineTrajectory tr = longPath();
  ImuModelConfig c;
  c.gyro_bias_random_walk = c.accel_bias_random_walk = 0;
  c.initial_gyro_bias.setZero();
  c.initial_accel_bias.setZero();
  const auto e = errors(simulateImu(tr, c, 42), simulateImu(tr, noiseFree(c.rate_hz), 42));
  const double n = static_cast<double>(e.size());
  ASSERT_GT(n, 20000);
  for (int ch = 0; ch < 6; ++ch) {
    const double sigma = (ch < 3 ? c.gyro_noise_density : c.accel_noise_density) * std::sqrt(c.rate_hz);
    double sum = 0, sum2 = 0, lag = 0;
    for (std::size_t k = 0; k < e.size(); ++k) {
      sum += e[k][ch];
      sum2 += e[k][ch] * e[k][ch];
      if (k > 0) lag += e[k][ch] * e[k - 1][ch];
    }
    const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
    EXPECT_NEAR(sd / sigma, 1.0, 0.05) << "channel " << ch;           // ~10 standard errors
    EXPECT_LT(std::abs(mean), 5 * sigma / std::sqrt(n)) << "channel " << ch;
    EXPECT_LT(std::abs(lag / n) / (sigma * sigma), 5 / std::sqrt(n)) << "channel " << ch;  // white
  }
}

TEST(ImuModel, BiasRandomWalkStartsAtTheInitialBiasAndItsVarianceGrowsAsSigmaSquaredTimesT) {
  const SplineTrajectory tr = splineOf([](double t) { return PathSample{0, {t, 0, 0}, 0.1 * t, 0, 0}; }, kSec / 2, 5);
  ImuModelConfig c;
  c.gyro_noise_density = c.accel_noise_density = 0;  // meas - truth is then the bias alone
  const auto truth = simulateImu(tr, noiseFree(c.rate_hz), 0);
  const std::size_t checkpoints[3] = {100, 200, 400};  // 0.5, 1, 2 s at 200 Hz
  double var[3][2] = {};                               // [checkpoint][gyro, accel]
  const int seeds = 1000;
  for (int seed = 0; seed < seeds; ++seed) {
    const auto e = errors(simulateImu(tr, c, static_cast<std::uint64_t>(seed)), truth);
    ASSERT_LT((e[0].head<3>() - c.initial_gyro_bias).norm(), 1e-15);
    ASSERT_LT((e[0].tail<3>() - c.initial_accel_bias).norm(), 1e-15);
    for (int i = 0; i < 3; ++i) {
      const Vector6d walk = e[checkpoints[i]] - e[0];
      var[i][0] += walk.head<3>().squaredNorm() / (3.0 * seeds);
      var[i][1] += walk.tail<3>().squaredNorm() / (3.0 * seeds);
    }
  }
  // 3000 pooled values per estimate: relative standard error sqrt(2 / 3000) = 2.6 %.
  for (int i = 0; i < 3; ++i) {
    const double T = static_cast<double>(checkpoints[i]) / c.rate_hz;
    EXPECT_NEAR(var[i][0] / (c.gyro_bias_random_walk * c.gyro_bias_random_walk * T), 1.0, 0.12) << T;
    EXPECT_NEAR(var[i][1] / (c.accel_bias_random_walk * c.accel_bias_random_walk * T), 1.0, 0.12) << T;
  }
}

TEST(ImuModel, SameSeedGivesIdenticalSamplesAndAnotherSeedDifferentOnes) {
  const SplineTrajectory tr = demandingPath();
  const ImuModelConfig c;
  const auto a = simulateImu(tr, c, 5), b = simulateImu(tr, c, 5), d = simulateImu(tr, c, 6);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), d.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].t, b[k].t);
    EXPECT_TRUE(a[k].omega_imu == b[k].omega_imu && a[k].acc_imu == b[k].acc_imu) << k;
    if (a[k].omega_imu != d[k].omega_imu && a[k].acc_imu != d[k].acc_imu) ++differing;
  }
  EXPECT_EQ(differing, a.size());
}

TEST(ImuModel, InvalidConfigIsRejectedNamingTheValue) {
  ImuModelConfig c;
  EXPECT_EQ(c.validate(), "");
  c.rate_hz = 0;
  EXPECT_NE(c.validate().find("rate_hz"), std::string::npos);
  const SplineTrajectory tr = splineOf([](double) { return PathSample{}; }, kSec, 4);
  EXPECT_THROW(simulateImu(tr, c, 1), std::invalid_argument);
  c = ImuModelConfig{};
  c.accel_noise_density = -1e-3;
  EXPECT_NE(c.validate().find("accel_noise_density"), std::string::npos);
  c = ImuModelConfig{};
  c.gyro_bias_random_walk = std::nan("");
  EXPECT_NE(c.validate().find("gyro_bias_random_walk"), std::string::npos);
  c = ImuModelConfig{};
  c.gyro_noise_density = 0;  // zero noise is allowed
  EXPECT_EQ(c.validate(), "");
}
