// A lidar-inertial start in motion (OdometryConfig::moving_start_restart): the IMU window at the first sweep is not
// static, so the smoother starts at rest and the first sweep's map is smeared by the motion it did not know. The
// smoother restarts a few sweeps later with the lidar's velocity; without the restart the first sweeps' velocity
// mismatch went into the accelerometer bias, which before the vehicle turns is a tilt (kitti05-replay, starting at
// 5.4 m/s: -0.2 m/s^2, 1-2 deg of pitch, 4.8 m of height lost in the first minute).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "pipeline/lidar_odometry.hpp"
#include "sim/simulator.hpp"
#include "support/sharp_turns_course.hpp"

namespace drover::pipeline {
namespace {

constexpr double kStart = 6.0;  // [s] into the sharp-turns course: on its straight at ~1.2 m/s, 7.5 s before a turn

// The straight of the sharp-turns course (at rest for 2.5 s, 11 m straight, a turn from 13.5 s), VLP-16 and IMU, no
// camera; the measurements before kStart dropped.
const test::LiveCourse& movingCourse() {
  static const test::LiveCourse c = test::sharpTurnsCourse(13.0, kStart);
  return c;
}

OdometryConfig movingStartConfig(int moving_start_restart) {
  OdometryConfig c = test::simOdometryConfig();
  c.moving_start_restart = moving_start_restart;
  return c;
}

// The truth's velocity at t [m/s] (central difference of its 200 Hz positions).
Eigen::Vector3d movingTruthVelocity(Time t) {
  const Trajectory& truth = movingCourse().truth;
  const auto it = test::truthFrom(truth, t);
  const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - truth.begin()), 1, truth.size() - 2);
  return (truth[i + 1].T_world_body.translation() - truth[i - 1].T_world_body.translation()) /
         toSeconds(truth[i + 1].t - truth[i - 1].t);
}

struct StartRun {
  std::string imu_init;
  double velocity_rms = 0;  // [m/s] smoother's velocity against the truth, sweeps from 1 s after the start
  double max_acc_bias_error = 0;  // [m/s^2] largest |acc bias - the simulator's| over those sweeps
  double max_tilt_error = 0;      // [rad] largest angle between the estimated and the true "up" over those sweeps
};

// The truth's pose at t (nearest 200 Hz sample).
const Eigen::Isometry3d& movingTruthAt(Time t) {
  const Trajectory& truth = movingCourse().truth;
  const auto it = test::truthFrom(truth, t);
  return (it == truth.end() ? truth.back() : *it).T_world_body;
}

StartRun runFromMovingStart(int moving_start_restart) {
  LidarOdometry odometry(movingStartConfig(moving_start_restart), movingCourse().calibration);
  std::vector<ScanOutcome> outcomes;
  for (const Measurement& m : movingCourse().stream)
    for (ScanOutcome& o : odometry.process(m)) outcomes.push_back(std::move(o));
  for (ScanOutcome& o : odometry.finish()) outcomes.push_back(std::move(o));
  const Eigen::Isometry3d T_lidar_imu = movingCourse().calibration.T_imu_lidar.inverse();
  StartRun r;
  r.imu_init = odometry.stats().imu_init;
  const Eigen::Vector3d true_acc_bias = sim::SimulatorConfig::defaults().imu.initial_accel_bias;
  double sum_sq = 0;
  int n = 0;
  for (const ScanOutcome& o : outcomes) {
    if (!o.has_imu_state || o.t < fromSeconds(kStart + 1.0)) continue;
    sum_sq += (o.v_world - movingTruthVelocity(o.t)).squaredNorm();
    ++n;
    r.max_acc_bias_error = std::max(r.max_acc_bias_error, (o.acc_bias - true_acc_bias).norm());
    // Up in the IMU frame, estimated and true: the tilt the accelerometer bias trades with.
    const Eigen::Matrix3d R_est = (o.T_world_lidar * T_lidar_imu).linear(), R_true = movingTruthAt(o.t).linear();
    const Eigen::Vector3d up_est = R_est.transpose().col(2), up_true = R_true.transpose().col(2);
    r.max_tilt_error = std::max(r.max_tilt_error, std::acos(std::clamp(up_est.dot(up_true), -1.0, 1.0)));
  }
  r.velocity_rms = n > 0 ? std::sqrt(sum_sq / n) : 1e9;
  std::printf(
      "moving_start_restart %d: velocity rms %.4f m/s, max acc bias error %.4f m/s^2, max tilt error %.3f deg over "
      "%d sweeps\n  %s\n",
      moving_start_restart, r.velocity_rms, r.max_acc_bias_error, r.max_tilt_error * 180 / M_PI, n, r.imu_init.c_str());
  return r;
}

TEST(MovingStart, AtTheSpeedTheLidarMeasuresTheSmootherRestartsAndKeepsVelocityAndTiltTrue) {
  ASSERT_GT(movingTruthVelocity(fromSeconds(kStart)).norm(), 1.0) << "the course must be moving at the first sweep";
  const StartRun restarted = runFromMovingStart(OdometryConfig{}.moving_start_restart);
  // At a constant 1.2 m/s the IMU window looks static: the lidar is what says the start was moving.
  EXPECT_NE(restarted.imu_init.find("by the lidar: the smoother restarted"), std::string::npos) << restarted.imu_init;
  EXPECT_LT(restarted.velocity_rms, 0.025);
  EXPECT_LT(restarted.max_tilt_error, 0.4 * M_PI / 180);  // the 9-axis orientation's own error at the start
  EXPECT_LT(restarted.max_acc_bias_error, 0.06);

  // The start at rest kept: the same course's velocity and tilt are worse (what the restart is for).
  const StartRun at_rest = runFromMovingStart(0);
  EXPECT_EQ(at_rest.imu_init.find("restarted"), std::string::npos) << at_rest.imu_init;
  EXPECT_GT(at_rest.velocity_rms, 2 * restarted.velocity_rms);
  EXPECT_GT(at_rest.max_tilt_error, 1.5 * restarted.max_tilt_error);
}

TEST(MovingStart, AStartAtRestIsNotRestarted) {
  const test::LiveCourse at_rest = test::sharpTurnsCourse(2.0);  // at rest for its first 2.5 s
  LidarOdometry odometry(movingStartConfig(OdometryConfig{}.moving_start_restart), at_rest.calibration);
  for (const Measurement& m : at_rest.stream) odometry.process(m);
  odometry.finish();
  const std::string& note = odometry.stats().imu_init;
  EXPECT_NE(note.find("static start"), std::string::npos) << note;
  EXPECT_EQ(note.find("restarted"), std::string::npos) << note;
  EXPECT_EQ(odometry.stats().smoother_resets, 0u);
}

}  // namespace
}  // namespace drover::pipeline
