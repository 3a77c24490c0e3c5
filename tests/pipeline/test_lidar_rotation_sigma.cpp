// The scan match's attitude in the IMU smoother (pipeline::ImuFusion): odometry.lidar_sigma_rotation, and
// lidar_sigma_rotation_unaided on a degenerate sweep that no relative factor aids. Exact IMU; from kTiltFrom on the
// matches are degenerate along x and pitched 1 deg off the truth (a map built on a tilt). Held tightly, the smoother
// follows the match's pitch; held loosely it keeps the IMU's (its gyro is exact, so the truth). A VIS that agrees with
// the truth and enters as the VO factor makes the sweep aided: the tight sigma holds there again.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <vector>

#include "pipeline/imu_fusion.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "sim/trajectory.hpp"
#include "support/rest_then_walk.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kSec;
constexpr Time kSweep = kSec / 10;     // 10 Hz lidar
constexpr Time kFrame = kSec / 15;     // 15 Hz camera
constexpr Time kTiltFrom = 4 * kSec;   // degenerate and tilted matches from here
constexpr Time kUntil = 7 * kSec;
constexpr double kTiltDeg = 1.0;

// The smoother's pitch error [deg] at kUntil.
double pitchErrorDeg(double sigma_rotation, double sigma_unaided, bool with_vis) {
  const sim::SplineTrajectory path = test::restThenWalk(8);  // rest, then 1 m/s along x
  const std::vector<ImuSample> imu = test::exactImu(path);
  OdometryConfig config;
  config.use_imu = true;
  config.lidar_sigma_rotation = sigma_rotation;
  config.lidar_sigma_rotation_unaided = sigma_unaided;
  config.vis_fusion.factor_degenerate_only = true;
  ImuFusion fusion(config, Eigen::Isometry3d::Identity());
  std::size_t next_imu = 0;
  Time next_frame = 0;
  const auto feedUntil = [&](Time t) {
    for (; next_imu < imu.size() && imu[next_imu].t <= t; ++next_imu) fusion.addImu(imu[next_imu]);
    for (; with_vis && next_frame <= t; next_frame += kFrame) {
      const sim::BodyState b = path.at(next_frame);
      fusion.addVisualState({next_frame, b.T_world_body, b.v_world, imu::ImuBias{}, 120, 1, 0, next_frame, kFrame,
                             std::nullopt});
    }
  };
  feedUntil(fromSeconds(config.initializer.window_s) + kSweep);
  fusion.tryInitialize(0, true);
  EXPECT_TRUE(fusion.initialized()) << fusion.initNote();
  const Eigen::Isometry3d T_start = fusion.initialLidarPose();  // the truth starts at the identity
  Trajectory trajectory;
  int factors = 0;
  for (Time t = 0; t <= kUntil; t += kSweep) {
    feedUntil(t);
    ScanOutcome out;
    out.t = t;
    out.T_world_lidar = T_start * path.at(t).T_world_body;
    out.match_usable = out.converged = true;
    if (t > kTiltFrom) {
      out.T_world_lidar.linear() =
          out.T_world_lidar.linear() * Eigen::AngleAxisd(kTiltDeg * M_PI / 180, Eigen::Vector3d::UnitY()).matrix();
      out.degenerate = true;
      out.degenerate_count = 1;
      out.degenerate_directions.push_back((Eigen::Matrix<double, 6, 1>() << 1, 0, 0, 0, 0, 0).finished());
    }
    fusion.update(out, trajectory);
    factors += out.vis_factor ? 1 : 0;
    trajectory.push_back({t, out.T_world_lidar});
  }
  EXPECT_EQ(factors > 0, with_vis) << "the VIS's motion is a factor on the degenerate sweeps when it runs";
  const std::optional<imu::FusedState> fused = fusion.fusedState();
  EXPECT_TRUE(fused.has_value());
  if (!fused) return NAN;
  const Eigen::Matrix3d R_truth = T_start.linear() * path.at(fused->state.t).T_world_body.linear();
  const Eigen::Matrix3d dR = R_truth.transpose() * fused->state.T_world_imu.linear();
  return std::asin(dR(0, 2)) * 180 / M_PI;  // rotation about y: dR(0, 2) = sin(pitch)
}

TEST(LidarRotationSigma, AnUnaidedDegenerateSweepLeavesThePitchToTheImuWhenItsSigmaIsLoose) {
  const double tight = pitchErrorDeg(0.002, 0.0, false);  // unaided = the same tight sigma
  const double loose = pitchErrorDeg(0.002, 0.5, false);
  EXPECT_GT(tight, 0.5 * kTiltDeg) << "held at 0.002 rad the smoother follows the tilted matches: " << tight;
  EXPECT_LT(std::abs(loose), 0.1 * kTiltDeg) << "at 0.5 rad the exact gyro keeps the truth: " << loose;
}

TEST(LidarRotationSigma, TheVisFactorMakesADegenerateSweepAidedAndTheTightSigmaHolds) {
  const double aided = pitchErrorDeg(0.002, 0.5, true);
  EXPECT_GT(aided, 0.5 * kTiltDeg) << "with the VO factor the tight sigma applies, not the unaided one: " << aided;
}

}  // namespace
}  // namespace drover::pipeline
