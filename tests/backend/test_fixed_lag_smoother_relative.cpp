// The fixed-lag smoother with a relative pose measurement between consecutive states (the VIS's motion between
// two sweeps, LVI-SAM's visual odometry factor): it carries the motion along a direction the pose measurement
// leaves free (a lidar-degenerate corridor axis), and the marginalisation keeps it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "backend/fixed_lag_smoother.hpp"
#include "backend/pose_factors.hpp"
#include "smoother_test_util.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

// A corridor along world x: the pose measurement says nothing of x (0 under a sigma of 1 km), the rest as lidar
// gives it (2 cm, 0.005 rad). The smoother starts with zero biases, so the IMU alone integrates its accelerometer-bias
// error along x.
Eigen::Isometry3d corridorPose(Eigen::Isometry3d T) {
  T.translation().x() = 0;
  return T;
}

Matrix6d corridorSqrtInformation() {
  Matrix6d L = poseSqrtInformation(0.02, 0.005);
  L(0, 0) = 1e-3;  // world x
  return L;
}

// The true motion between t0 and t1 with a right-perturbed 0.002 rad rotation and 5 mm translation error.
RelativePoseMeasurement visualMotion(const Scenario& s, Time t0, Time t1, PoseNoise& noise) {
  RelativePoseMeasurement m;
  m.T_i_j = noise.apply(s.truth(t0).T_world_imu.inverse() * s.truth(t1).T_world_imu);
  m.sqrt_information = poseSqrtInformation(0.01, 0.004);
  return m;
}

struct CorridorRun {
  double x_error = 0;  // [m] |x - x_true| of the newest state after 10 s
  double worst_x_error = 0;
  imu::NavState state;
  imu::ImuBias bias;
};

CorridorRun runCorridor(int window, bool with_visual, int updates = 100) {
  const Scenario s;
  FixedLagSmoother::Config config;
  config.window = window;
  FixedLagSmoother smoother(config);
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  PoseNoise lidar_noise, visual_noise;
  lidar_noise.sigma_position = 0.02;
  visual_noise.sigma_position = 0.005;
  visual_noise.sigma_rotation = 0.002;
  visual_noise.rng.seed(29);
  CorridorRun r;
  for (int k = 1; k <= updates; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    const imu::Preintegrator pim = preintegrate(s, t0, t1, smoother.bias());
    std::optional<RelativePoseMeasurement> visual;
    if (with_visual) visual = visualMotion(s, t0, t1, visual_noise);
    const SmootherUpdate u =
        smoother.update(pim, corridorPose(lidar_noise.apply(s.truth(t1).T_world_imu)), corridorSqrtInformation(), visual);
    EXPECT_TRUE(u.ok) << "update " << k << ": " << u.reason;
    r.x_error = std::abs(u.state.T_world_imu.translation().x() - s.truth(t1).T_world_imu.translation().x());
    r.worst_x_error = std::max(r.worst_x_error, r.x_error);
  }
  r.state = smoother.state();
  r.bias = smoother.bias();
  return r;
}

}  // namespace

TEST(FixedLagSmootherRelative, TheVisualMotionCarriesTheStateAlongTheAxisThePoseMeasurementLeavesFree) {
  const CorridorRun imu_only = runCorridor(10, false);
  const CorridorRun fused = runCorridor(10, true);
  std::printf("x error after 10 s along the free axis (20 m): IMU only %.3f m (worst %.3f), with the visual motion "
              "%.3f m (worst %.3f)\n",
              imu_only.x_error, imu_only.worst_x_error, fused.x_error, fused.worst_x_error);
  // Measured 0.62 m IMU only (the accelerometer-bias error integrates) and 0.032 m with the visual increments
  // (5 mm each over 100 steps, a random walk of ~5 cm).
  EXPECT_GT(imu_only.worst_x_error, 0.3);
  EXPECT_LT(fused.worst_x_error, 0.06);
}

TEST(FixedLagSmootherRelative, MarginalisingAStateKeepsItsRelativePoseFactorAShortWindowMatchesTheBatch) {
  // The relative factor between the dropped state and the next enters the Schur complement: a 3-state window
  // must end where the batch (nothing marginalised) ends, up to relinearisation. Were the factor dropped with the
  // state, the window would lose the corridor axis and follow the IMU (decimetres, test above).
  const CorridorRun short_window = runCorridor(3, true, 40);
  const CorridorRun batch = runCorridor(1000, true, 40);
  const double dp = (short_window.state.T_world_imu.translation() - batch.state.T_world_imu.translation()).norm();
  const double dv = (short_window.state.v_world - batch.state.v_world).norm();
  const double dba = (short_window.bias.acc - batch.bias.acc).norm();
  std::printf("window 3 vs batch 41 with relative factors: |dp| %.2e m, |dv| %.2e m/s, |dba| %.2e m/s^2\n", dp, dv,
              dba);
  EXPECT_LT(dp, 2e-3);
  EXPECT_LT(dv, 2e-3);
  EXPECT_LT(dba, 2e-3);
}

TEST(FixedLagSmootherRelative, ANonFiniteRelativeMeasurementIsRefusedBeforeTheWindowChanges) {
  const Scenario s;
  FixedLagSmoother smoother;
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  RelativePoseMeasurement bad;
  bad.T_i_j.translation().x() = std::nan("");
  const imu::Preintegrator pim = preintegrate(s, 0, kLidarPeriod, imu::ImuBias{});
  EXPECT_THROW(smoother.update(pim, s.truth(kLidarPeriod).T_world_imu, poseSqrtInformation(0.05, 0.05), bad),
               std::invalid_argument);
  EXPECT_EQ(smoother.size(), 1);
}

namespace {

// At rest at the origin for 3 s with the pose measurement free along x and an accelerometer bias of 0.02 m/s^2
// along x the smoother does not know (standing still it cannot be told from a velocity): the IMU creeps by
// 1/2 b t^2 = 9 cm. Then 1 s of visual motion saying "no motion". Returns |x| [m] at the end (the truth is 0).
double creepLeftAfterTheVisualMotion(std::optional<double> first_velocity_sigma) {
  const imu::PreintegrationConfig imu_config;
  FixedLagSmoother smoother;
  smoother.initialize(imu::NavState{}, imu::ImuBias{}, imu_config);
  if (first_velocity_sigma) smoother.setFirstVelocitySigma(*first_velocity_sigma);
  RelativePoseMeasurement still;
  still.sqrt_information = poseSqrtInformation(0.01, 0.004);
  SmootherUpdate u;
  for (int k = 1; k <= 40; ++k) {
    imu::Preintegrator pim(smoother.bias(), imu_config);
    for (int i = 0; i < 20; ++i) pim.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.02, 0, 9.81), 0.005);
    u = smoother.update(pim, Eigen::Isometry3d::Identity(), corridorSqrtInformation(),
                        k > 30 ? std::optional<RelativePoseMeasurement>(still) : std::nullopt);
    EXPECT_TRUE(u.ok) << u.reason;
  }
  return std::abs(u.state.T_world_imu.translation().x());
}

}  // namespace

// The state at rest at the start is known, not merely unknown around zero (pipeline's static_start_sigma_velocity):
// when a velocity measurement arrives later, the creep can then only have been the accelerometer bias, and the
// smoother takes it out; with the loose first velocity (1 m/s) it may as well have been a velocity since the start.
TEST(FixedLagSmootherRelative, AFirstVelocityKnownAtRestLetsLaterVisualMotionTakeOutTheBiasCreep) {
  const double known = creepLeftAfterTheVisualMotion(0.01);
  const double loose = creepLeftAfterTheVisualMotion(std::nullopt);
  std::printf("x error after 3 s of creep and 1 s of visual motion: first velocity known %.3f m, loose %.3f m\n", known,
              loose);
  EXPECT_LT(known, 0.03);
  EXPECT_GT(loose, known + 0.02);
}

TEST(FixedLagSmootherRelative, TheFirstVelocitySigmaIsSetOnlyOnAFreshWindowAndMustBePositive) {
  const imu::PreintegrationConfig imu_config;
  FixedLagSmoother smoother;
  EXPECT_THROW(smoother.setFirstVelocitySigma(0.01), std::logic_error);
  smoother.initialize(imu::NavState{}, imu::ImuBias{}, imu_config);
  EXPECT_THROW(smoother.setFirstVelocitySigma(0.0), std::invalid_argument);
  EXPECT_THROW(smoother.setFirstVelocitySigma(std::nan("")), std::invalid_argument);
  EXPECT_NO_THROW(smoother.setFirstVelocitySigma(0.01));
  imu::Preintegrator pim(imu::ImuBias{}, imu_config);
  pim.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.81), 0.1);
  ASSERT_TRUE(smoother.update(pim, Eigen::Isometry3d::Identity()).ok);
  EXPECT_THROW(smoother.setFirstVelocitySigma(0.01), std::logic_error);
}
