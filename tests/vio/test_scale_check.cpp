// The scale check (vio/scale_check.hpp): a trajectory known up to a scale and a tilt of gravity, against the exact
// IMU of a car driving through bends for 15 s.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "geometry/so3.hpp"
#include "vio/scale_check.hpp"
#include "vio/vio_test_scene.hpp"
#include "support/units.hpp"

namespace drover::vio {
namespace {

using ::drover::test::kDeg;

// 15 s of keyframes at 4 Hz with exact (hold-equivalent) IMU samples; no features needed.
test::Scene scaleDrive(test::Motion motion) {
  test::SceneConfig config;
  config.motion = motion;
  config.frames = 61;
  config.camera_hz = 4;
  config.points = 0;
  config.hold_equivalent_samples = true;
  return test::makeScene(config);
}

// The truth as a monocular estimator with a wrong scale and tilt would have it: the camera's distances times
// `scale` about the last keyframe (the IMU follows at the metric lever arm), the world tilted by `tilt` about its x
// axis there; camera positions perturbed by `noise_m` (std, per axis).
std::vector<ScaleCheckFrame> estimated(const test::Scene& scene, double scale, double tilt, double noise_m = 0) {
  const Eigen::Matrix3d R_tilt = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Isometry3d T_ic = test::testImuCam();
  const Eigen::Vector3d pivot = (scene.T_world_imu.back() * T_ic).translation();
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, noise_m);
  std::vector<ScaleCheckFrame> frames;
  for (std::size_t k = 0; k < scene.frames.size(); ++k) {
    ScaleCheckFrame f;
    f.t = scene.frames[k].t;
    f.T_world_imu.linear() = R_tilt * scene.T_world_imu[k].linear();
    const Eigen::Vector3d c = pivot + R_tilt * (scale * ((scene.T_world_imu[k] * T_ic).translation() - pivot)) +
                              Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    f.T_world_imu.translation() = c - f.T_world_imu.linear() * T_ic.translation();
    f.bias.gyro = test::SceneConfig{}.gyro_bias;
    f.imu = scene.frames[k].imu;
    frames.push_back(f);
  }
  return frames;
}

TEST(ScaleCheck, FindsTheScaleAndTheTiltOfATrajectoryThatHasThemWrong) {
  const test::Scene scene = scaleDrive(test::Motion::kCarInABend);
  const ScaleCheck check = checkScale(estimated(scene, 0.8, 1.0 * kDeg), test::testImuCam(), {});
  ASSERT_TRUE(check.ok) << check.why;
  EXPECT_NEAR(check.scale, 1 / 0.8, 1e-3);
  EXPECT_NEAR(check.tilt_rad, 1.0 * kDeg, 0.01 * kDeg);
  EXPECT_LT(check.rel_sigma, 1e-3);
  // The velocities in the corrected world: the truth's, up to the yaw the check leaves alone (none here).
  ASSERT_EQ(check.v_world.size(), scene.v_world.size());
  for (std::size_t k = 0; k < scene.v_world.size(); ++k) {
    EXPECT_LT((check.v_world[k] - scene.v_world[k]).norm(), 0.01) << k;
  }
}

TEST(ScaleCheck, ARightTrajectoryIsLeftAlone) {
  const test::Scene scene = scaleDrive(test::Motion::kCarInABend);
  const ScaleCheck check = checkScale(estimated(scene, 1.0, 0.0, 0.01), test::testImuCam(), {});
  ASSERT_TRUE(check.ok) << check.why;
  EXPECT_NEAR(check.scale, 1.0, 3 * check.rel_sigma);
  EXPECT_LT(check.rel_sigma, 0.03);
  EXPECT_LT(check.tilt_rad, 0.2 * kDeg);
}

TEST(ScaleCheck, WithPositionNoiseTheScaleIsWithinItsSigma) {
  const test::Scene scene = scaleDrive(test::Motion::kCarInABend);
  const ScaleCheck check = checkScale(estimated(scene, 1.2, -0.5 * kDeg, 0.01), test::testImuCam(), {});
  ASSERT_TRUE(check.ok) << check.why;
  EXPECT_LT(check.rel_sigma, 0.03);
  EXPECT_NEAR(check.scale, 1 / 1.2, 3 * check.rel_sigma / 1.2);
  EXPECT_NEAR(check.tilt_rad, 0.5 * kDeg, 0.2 * kDeg);
}

TEST(ScaleCheck, AtConstantVelocityTheScaleIsReportedUndetermined) {
  // No acceleration: any scale explains the IMU, and the sigma must say so rather than the scale.
  const test::Scene scene = scaleDrive(test::Motion::kConstantVelocity);
  const ScaleCheck check = checkScale(estimated(scene, 0.8, 0.0, 0.02), test::testImuCam(), {});
  if (check.ok) {
    EXPECT_GT(check.rel_sigma, 0.1) << "scale " << check.scale;
  }
}

// The check's signal: the world-frame acceleration's std over the keyframe intervals, as the truth has it.
TEST(ScaleCheck, ReportsTheAccelerationStdItMeasuresTheScaleBy) {
  const test::Scene bend = scaleDrive(test::Motion::kCarInABend);
  std::vector<Eigen::Vector3d> a;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t k = 1; k < bend.v_world.size(); ++k) {
    a.push_back((bend.v_world[k] - bend.v_world[k - 1]) / toSeconds(bend.frames[k].t - bend.frames[k - 1].t));
    mean += a.back() / static_cast<double>(bend.v_world.size() - 1);
  }
  double var = 0;
  for (const Eigen::Vector3d& x : a) var += (x - mean).squaredNorm() / static_cast<double>(a.size());
  const ScaleCheck check = checkScale(estimated(bend, 1.0, 0.0), test::testImuCam(), {});
  ASSERT_TRUE(check.ok) << check.why;
  EXPECT_GT(check.acc_std, 0.3);
  EXPECT_NEAR(check.acc_std, std::sqrt(var), 0.02 * std::sqrt(var));
  const test::Scene steady = scaleDrive(test::Motion::kConstantVelocity);
  const ScaleCheck still = checkScale(estimated(steady, 1.0, 0.0), test::testImuCam(), {});
  EXPECT_LT(still.acc_std, 0.01);
}

// What the window's vio.scale_check_bias_sigma stands for: an accelerometer bias error the check does not estimate
// errs the scale by up to the error over the acceleration's std (here, in a bend, the tilt takes most of it).
TEST(ScaleCheck, AnUnmodelledAccelerometerBiasErrsTheScaleByLessThanItOverTheAccelerationStd) {
  const test::Scene scene = scaleDrive(test::Motion::kCarInABend);
  const double bias_error = 0.1;  // [m/s^2]
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<ScaleCheckFrame> frames = estimated(scene, 1.0, 0.0);
    for (ScaleCheckFrame& f : frames) f.bias.acc = bias_error * Eigen::Vector3d::Unit(axis);  // the IMU has none
    const ScaleCheck check = checkScale(frames, test::testImuCam(), {});
    ASSERT_TRUE(check.ok) << check.why;
    std::printf("bias error on axis %d: scale %.4f +- %.4f (residuals), acceleration std %.3f m/s^2\n", axis,
                check.scale, check.rel_sigma, check.acc_std);
    EXPECT_LT(std::abs(check.scale - 1.0), bias_error / check.acc_std) << "axis " << axis;
  }
}

TEST(ScaleCheck, ImuThatDoesNotCoverAnIntervalIsAnError) {
  const test::Scene scene = scaleDrive(test::Motion::kCarInABend);
  std::vector<ScaleCheckFrame> frames = estimated(scene, 1.0, 0.0);
  frames[5].imu.erase(frames[5].imu.begin());
  EXPECT_THROW(checkScale(frames, test::testImuCam(), {}), std::invalid_argument);
  frames.resize(2);
  EXPECT_FALSE(checkScale(frames, test::testImuCam(), {}).ok);
}

}  // namespace
}  // namespace drover::vio
