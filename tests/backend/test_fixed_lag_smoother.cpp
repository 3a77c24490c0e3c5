#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>

#include <Eigen/Eigenvalues>

#include "backend/fixed_lag_smoother.hpp"
#include "backend/pose_factors.hpp"
#include "geometry/so3.hpp"
#include "sim/imu_model.hpp"
#include "sim/trajectory.hpp"
#include "smoother_test_util.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

bool finite(const imu::NavState& x, const imu::ImuBias& b) {
  return x.T_world_imu.matrix().allFinite() && x.v_world.allFinite() && b.gyro.allFinite() && b.acc.allFinite();
}

}  // namespace

TEST(FixedLagSmoother, RecoversVelocityAndConstantBiasesFromNoisyImuAndLidarPosesWithinTenSeconds) {
  const Scenario s;
  FixedLagSmoother smoother;  // window 10
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  PoseNoise noise;
  const Matrix6d L = poseSqrtInformation(noise.sigma_position, noise.sigma_rotation);
  double worst_ms = 0, total_ms = 0;
  int max_iterations = 0, sum_iterations = 0;
  const int updates = 100;
  for (int k = 1; k <= updates; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    const imu::Preintegrator pim = preintegrate(s, t0, t1, smoother.bias());
    const auto start = std::chrono::steady_clock::now();
    const SmootherUpdate u = smoother.update(pim, noise.apply(s.truth(t1).T_world_imu), L);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    worst_ms = std::max(worst_ms, ms);
    total_ms += ms;
    max_iterations = std::max(max_iterations, u.iterations);
    sum_iterations += u.iterations;
    ASSERT_TRUE(u.ok) << "update " << k << ": " << u.reason;
    ASSERT_FALSE(u.failure);
    ASSERT_EQ(u.state.t, t1);
    ASSERT_TRUE(finite(u.state, u.bias));
    ASSERT_EQ(smoother.size(), std::min(k + 1, 10)) << "window not respected at update " << k;
    ASSERT_LE(u.final_cost, u.initial_cost + 1e-9);
  }
  const imu::NavState truth = s.truth(updates * kLidarPeriod);
  const double v_error = (smoother.state().v_world - truth.v_world).norm();
  const double p_error = (smoother.state().T_world_imu.translation() - truth.T_world_imu.translation()).norm();
  const double bg_error = (smoother.bias().gyro - s.imu_model.initial_gyro_bias).norm();
  const double ba_error = (smoother.bias().acc - s.imu_model.initial_accel_bias).norm();
  std::printf("after 10 s: |dv| %.4f m/s, |dp| %.4f m, |dbg| %.2e rad/s, |dba| %.4f m/s^2; update %.2f ms mean, "
              "%.2f ms worst, %.1f iterations mean, %d max\n",
              v_error, p_error, bg_error, ba_error, total_ms / updates, worst_ms,
              double(sum_iterations) / updates, max_iterations);
  EXPECT_LT(v_error, 0.05);
  EXPECT_LT(bg_error, 2e-3);
  EXPECT_LT(ba_error, 0.05);
  EXPECT_LT(p_error, 0.05);
}

TEST(FixedLagSmoother, SchurMarginalisationOfAShortWindowMatchesTheFullBatchSolution) {
  // A linear(ised) Gaussian problem marginalised by the Schur complement loses nothing: a 3-state window must
  // end where the 31-state batch (nothing marginalised) ends, up to the relinearisation of the dropped states.
  const Scenario s;
  FixedLagSmoother::Config short_window, batch;
  short_window.window = 3;
  batch.window = 1000;
  FixedLagSmoother a(short_window), b(batch);
  a.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  b.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  PoseNoise noise;
  for (int k = 1; k <= 30; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    const imu::Preintegrator pim = preintegrate(s, t0, t1, imu::ImuBias{});
    const Eigen::Isometry3d T = noise.apply(s.truth(t1).T_world_imu);
    ASSERT_TRUE(a.update(pim, T).ok);
    ASSERT_TRUE(b.update(pim, T).ok);
  }
  EXPECT_EQ(a.size(), 3);
  EXPECT_EQ(b.size(), 31);
  const double dp = (a.state().T_world_imu.translation() - b.state().T_world_imu.translation()).norm();
  const double dv = (a.state().v_world - b.state().v_world).norm();
  const double dbg = (a.bias().gyro - b.bias().gyro).norm(), dba = (a.bias().acc - b.bias().acc).norm();
  std::printf("window 3 vs batch 31: |dp| %.2e m, |dv| %.2e m/s, |dbg| %.2e rad/s, |dba| %.2e m/s^2\n", dp, dv,
              dbg, dba);
  EXPECT_LT(dp, 1e-3);
  EXPECT_LT(dv, 1e-3);
  EXPECT_LT(dbg, 1e-4);
  EXPECT_LT(dba, 1e-3);
}

TEST(FixedLagSmoother, APoseMeasurementHundredMetresOffIsReportedAsFailureAndRolledBack) {
  const Scenario s;
  FixedLagSmoother smoother;
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  PoseNoise noise;
  for (int k = 1; k <= 10; ++k) {
    const imu::Preintegrator pim = preintegrate(s, (k - 1) * kLidarPeriod, k * kLidarPeriod, smoother.bias());
    ASSERT_TRUE(smoother.update(pim, noise.apply(s.truth(k * kLidarPeriod).T_world_imu)).ok);
  }
  const imu::NavState good = smoother.state();
  const int size = smoother.size();
  Eigen::Isometry3d wild = s.truth(11 * kLidarPeriod).T_world_imu;
  wild.translation().x() += 100.0;
  const SmootherUpdate u =
      smoother.update(preintegrate(s, 10 * kLidarPeriod, 11 * kLidarPeriod, smoother.bias()), wild);
  std::printf("failure reason: %s\n", u.reason.c_str());
  EXPECT_TRUE(u.failure);
  EXPECT_FALSE(u.ok);
  EXPECT_NE(u.reason.find("velocity"), std::string::npos) << u.reason;
  EXPECT_TRUE(finite(u.state, u.bias));
  EXPECT_EQ(u.state.t, good.t);  // the last good state, the window rolled back
  EXPECT_EQ(smoother.size(), size);
  EXPECT_LT((smoother.state().T_world_imu.translation() - good.T_world_imu.translation()).norm(), 1e-12);
  smoother.reset();
  EXPECT_FALSE(smoother.initialized());
  EXPECT_EQ(smoother.size(), 0);
}

TEST(FixedLagSmoother, RejectsInvalidConfigsAndUpdatesBeforeInitialisation) {
  FixedLagSmoother::Config c;
  EXPECT_EQ(c.validate(), "");
  c.window = 1;
  c.lidar_sigma_position = -1;
  EXPECT_NE(c.validate().find("window = 1"), std::string::npos);
  EXPECT_NE(c.validate().find("lidar_sigma_position"), std::string::npos);
  EXPECT_THROW(FixedLagSmoother{c}, std::invalid_argument);

  FixedLagSmoother smoother;
  const imu::PreintegrationConfig imu_config;
  imu::Preintegrator pim(imu::ImuBias{}, imu_config);
  pim.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81), 0.1);
  EXPECT_FALSE(smoother.initialized());
  EXPECT_THROW(smoother.update(pim, Eigen::Isometry3d::Identity()), std::invalid_argument);
  EXPECT_THROW(smoother.state(), std::logic_error);
  smoother.initialize(imu::NavState{}, imu::ImuBias{}, imu_config);
  const imu::Preintegrator empty(imu::ImuBias{}, imu_config);
  EXPECT_THROW(smoother.update(empty, Eigen::Isometry3d::Identity()), std::invalid_argument);
  // A robot at rest measured at rest stays at rest.
  const SmootherUpdate u = smoother.update(pim, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(u.ok) << u.reason;
  EXPECT_EQ(u.state.t, fromSeconds(0.1));
  EXPECT_LT(u.state.v_world.norm(), 1e-6);
  EXPECT_LT(u.state.T_world_imu.translation().norm(), 1e-6);
}

// A restart in a world a loop correction moved: the state turned and shifted, its bias kept.
void restartMoved(FixedLagSmoother& smoother, const Eigen::Isometry3d& T_new_old, const imu::PreintegrationConfig& imu,
                  bool keep_gyro_certainty) {
  const std::optional<Eigen::Matrix3d> gyro = smoother.gyroBiasCovariance();
  ASSERT_TRUE(gyro.has_value());
  imu::NavState x = smoother.state();
  x.T_world_imu = T_new_old * x.T_world_imu;
  x.v_world = T_new_old.linear() * x.v_world;
  const imu::ImuBias b = smoother.bias();
  smoother.reset();
  if (keep_gyro_certainty) smoother.initialize(x, b, imu, *gyro);
  else smoother.initialize(x, b, imu);
}

TEST(FixedLagSmoother, TheGyroBiasCovarianceIsTheWindowsCertaintyAndItsErrorLiesWithinIt) {
  // After 10 s of noisy IMU and lidar poses the gyro bias is known far better than the first-state prior
  // (0.01 rad/s), and the estimate's error is what the covariance says it may be (within 4 sigma per axis).
  const Scenario s;
  FixedLagSmoother smoother;
  EXPECT_FALSE(smoother.gyroBiasCovariance().has_value());  // not initialized
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  PoseNoise noise;
  for (int k = 1; k <= 100; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    ASSERT_TRUE(smoother.update(preintegrate(s, t0, t1, smoother.bias()), noise.apply(s.truth(t1).T_world_imu)).ok);
  }
  const std::optional<Eigen::Matrix3d> C = smoother.gyroBiasCovariance();
  ASSERT_TRUE(C.has_value());
  const Eigen::Vector3d sigma = C->diagonal().cwiseSqrt();
  const Eigen::Vector3d error = smoother.bias().gyro - s.imu_model.initial_gyro_bias;
  std::printf("gyro bias sigma %.1e %.1e %.1e rad/s, error %.1e %.1e %.1e rad/s\n", sigma.x(), sigma.y(), sigma.z(),
              error.x(), error.y(), error.z());
  EXPECT_LT((*C - C->transpose()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(*C).eigenvalues().minCoeff(), 0.0);
  EXPECT_LT(sigma.maxCoeff(), 0.2 * 0.01);
  for (int i = 0; i < 3; ++i) EXPECT_LT(std::abs(error[i]), 4 * sigma[i]) << "axis " << i;
  // A covariance that is not one is refused.
  FixedLagSmoother other;
  EXPECT_THROW(
      other.initialize(s.truth(0), imu::ImuBias{}, s.preintegration, Eigen::Matrix3d(-Eigen::Matrix3d::Identity())),
      std::invalid_argument);
  EXPECT_THROW(
      other.initialize(s.truth(0), imu::ImuBias{}, s.preintegration, Eigen::Matrix3d(Eigen::Matrix3d::Constant(NAN))),
      std::invalid_argument);
}

// Feeds `kept` and `loose` (both initialised at the start) 12 s of the scenario, 120 sweeps. From sweep 71 on, every
// 5th sweep a loop correction (0.02 rad of yaw and a few cm) moves the smoothers' world and restart(smoother, T,
// keep_certainty) restarts each there; perturb(k, measured) alters the lidar pose of every sweep k > 70; after(k)
// is called once both have taken sweep k.
template <typename Restart, typename Perturb, typename After>
void runWithLoopRestarts(const Scenario& s, FixedLagSmoother& kept, FixedLagSmoother& loose, Restart restart,
                         Perturb perturb, After after) {
  PoseNoise noise;
  Eigen::Isometry3d T_world_truth = Eigen::Isometry3d::Identity();  // the smoothers' world, from the truth's
  for (int k = 1; k <= 120; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    if (k > 70 && k % 5 == 0) {
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = geometry::expSO3(Eigen::Vector3d(0, 0, 0.02));
      T.translation() = Eigen::Vector3d(0.05, 0.02, -0.01);
      T_world_truth = T * T_world_truth;
      restart(kept, T, true);
      restart(loose, T, false);
    }
    Eigen::Isometry3d measured = T_world_truth * noise.apply(s.truth(t1).T_world_imu);
    if (k > 70) perturb(k, T_world_truth, measured);
    ASSERT_TRUE(kept.update(preintegrate(s, t0, t1, kept.bias()), measured).ok) << k;
    ASSERT_TRUE(loose.update(preintegrate(s, t0, t1, loose.bias()), measured).ok) << k;
    after(k);
  }
}

TEST(FixedLagSmoother, RestartedAtEveryLoopWithItsGyroCertaintyItHoldsTheBiasAgainstAHeadingWalk) {
  // The farm's second lap: loops every few seconds, and a stretch where the scan matcher's heading walks off.
  // After 7 s the gyro bias is known; then for 5 s the lidar's heading drifts at 0.003 rad/s, and every 0.5 s a loop
  // correction moves the world and the smoother restarts there. Restarted with the gyro bias covariance it had,
  // the bias holds; restarted with the first-state prior (0.01 rad/s, re-centred on the current estimate each
  // time), it follows the lidar's drift further.
  const Scenario s;
  FixedLagSmoother kept, loose;
  kept.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  loose.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  ASSERT_NO_FATAL_FAILURE(runWithLoopRestarts(
      s, kept, loose,
      [&](FixedLagSmoother& f, const Eigen::Isometry3d& T, bool keep) { restartMoved(f, T, s.preintegration, keep); },
      [](int k, const Eigen::Isometry3d&, Eigen::Isometry3d& measured) {
        measured.linear() = Eigen::AngleAxisd(0.003 * (k - 70) * 0.1, Eigen::Vector3d::UnitZ()) * measured.linear();
      },
      [](int) {}));
  const double kept_error = (kept.bias().gyro - s.imu_model.initial_gyro_bias).norm();
  const double loose_error = (loose.bias().gyro - s.imu_model.initial_gyro_bias).norm();
  std::printf("gyro bias error after 5 s of heading walk and 10 restarts: certainty kept %.2e, loose %.2e rad/s\n",
              kept_error, loose_error);
  EXPECT_LT(kept_error, 5e-4);
  EXPECT_LT(kept_error, 0.2 * loose_error);
}

TEST(FixedLagSmoother, RestartedAtEveryYawOnlyLoopWithBothBiasesCertaintyItHoldsTheAccelerometerBias) {
  // A 4-DoF pose graph turns the world about gravity only, which changes neither bias, so a restart may keep what
  // the window knew of both. After 7 s the biases are known; then for 5 s the lidar's position creeps along x at
  // 5 cm/s^2 of apparent acceleration (as a match that slides in a corridor), and every 0.5 s a yaw-only correction
  // restarts the smoother. With both biases' certainty kept the accelerometer bias holds; re-centred on the loose
  // first-state prior each time, it takes up the creep.
  const Scenario s;
  FixedLagSmoother kept, loose;
  kept.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  loose.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  Eigen::Vector3d before = Eigen::Vector3d::Zero();  // [m/s^2] the accelerometer bias when the creep starts
  const auto restart = [&](FixedLagSmoother& f, const Eigen::Isometry3d& T, bool keep) {
    const std::optional<Eigen::Matrix<double, 6, 6>> C = f.biasCovariance();
    ASSERT_TRUE(C.has_value());
    imu::NavState x = f.state();
    x.T_world_imu = T * x.T_world_imu;
    x.v_world = T.linear() * x.v_world;
    const imu::ImuBias b = f.bias();
    f.reset();
    if (keep) f.initialize(x, b, s.preintegration, *C);
    else f.initialize(x, b, s.preintegration);
  };
  const auto creep = [](int k, const Eigen::Isometry3d& T_world_truth, Eigen::Isometry3d& measured) {
    const double creep_s = (k - 70) * 0.1;
    measured.translation() += T_world_truth.linear() * Eigen::Vector3d(0.5 * 0.05 * creep_s * creep_s, 0, 0);
  };
  ASSERT_NO_FATAL_FAILURE(runWithLoopRestarts(s, kept, loose, restart, creep, [&](int k) {
    if (k == 70) before = kept.bias().acc;  // the same in both: no restart yet
  }));
  const double kept_moved = (kept.bias().acc - before).norm();
  const double loose_moved = (loose.bias().acc - before).norm();
  std::printf("acc bias moved in 5 s of creep and 10 yaw-only restarts: certainty kept %.2e, loose %.2e m/s^2 "
              "(error before %.2e)\n", kept_moved, loose_moved, (before - s.imu_model.initial_accel_bias).norm());
  EXPECT_LT(kept_moved, 0.3 * loose_moved);
  EXPECT_LT(kept_moved, 3e-3);
  // A covariance that is not one is refused.
  FixedLagSmoother other;
  EXPECT_THROW(other.initialize(s.truth(0), imu::ImuBias{}, s.preintegration,
                                Eigen::Matrix<double, 6, 6>(-Eigen::Matrix<double, 6, 6>::Identity())),
               std::invalid_argument);
}
