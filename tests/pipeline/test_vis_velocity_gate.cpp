// The VIS's velocity gate inside the LIS (pipeline::ImuFusion): its limit widens with the time since the smoother's
// velocity was last measured. A VIS 30 % slow is refused while the lidar holds the LIS, and half a second into a
// lidar-degenerate stretch; a second in, what the IMU alone may have carried the LIS off by (0.05 m/s^2)
// covers the difference and the VIS's motion becomes a factor. Exact sensors: the LIS follows the truth, the VIS is
// the one that is off.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pipeline/imu_fusion.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "sim/trajectory.hpp"
#include "support/rest_then_walk.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kSec;
constexpr Time kSweep = kSec / 10;       // 10 Hz lidar
constexpr Time kGateFrame = kSec / 15;       // 15 Hz camera
constexpr Time kBlindFrom = 5 * kSec;    // the VIS slows to 70 % here; the degenerate stretch starts here

// The VIS's state at t: the truth until kBlindFrom, then 70 % of the truth's motion and velocity.
VisualState slowVis(const sim::SplineTrajectory& path, Time t) {
  const sim::BodyState b = path.at(t);
  VisualState s{t, b.T_world_body, b.v_world, imu::ImuBias{}, 120, 1, 0, t, kGateFrame, std::nullopt};
  if (t > kBlindFrom) {
    const Eigen::Vector3d p0 = path.at(kBlindFrom).T_world_body.translation();
    s.T_world_imu.translation() = p0 + 0.7 * (b.T_world_body.translation() - p0);
    s.v_world = 0.7 * b.v_world;
  }
  return s;
}

// Sweeps up to `until` with the truth's pose; from kBlindFrom on degenerate along x when `blind`.
std::vector<ScanOutcome> run(Time until, bool blind) {
  const sim::SplineTrajectory path = test::restThenWalk(12);  // rest, then 1 m/s along x
  const std::vector<ImuSample> imu = test::exactImu(path);
  OdometryConfig config;
  config.use_imu = true;
  ImuFusion fusion(config, Eigen::Isometry3d::Identity());
  std::size_t next_imu = 0;
  Time next_frame = 0;
  const auto feedUntil = [&](Time t) {
    for (; next_imu < imu.size() && imu[next_imu].t <= t; ++next_imu) fusion.addImu(imu[next_imu]);
    for (; next_frame <= t; next_frame += kGateFrame) fusion.addVisualState(slowVis(path, next_frame));
  };
  feedUntil(fromSeconds(config.initializer.window_s) + kSweep);
  fusion.tryInitialize(0, true);
  EXPECT_TRUE(fusion.initialized()) << fusion.initNote();
  Trajectory trajectory;
  std::vector<ScanOutcome> outcomes;
  for (Time t = 0; t <= until; t += kSweep) {
    feedUntil(t);
    ScanOutcome out;
    out.t = t;
    out.T_world_lidar = fusion.initialLidarPose() * path.at(t).T_world_body;  // the truth starts at the identity
    out.match_usable = out.converged = true;
    if (blind && t > kBlindFrom) {
      out.degenerate = true;
      out.degenerate_count = 1;
      out.degenerate_directions.push_back((Eigen::Matrix<double, 6, 1>() << 1, 0, 0, 0, 0, 0).finished());
    }
    fusion.update(out, trajectory);
    trajectory.push_back({t, out.T_world_lidar});
    outcomes.push_back(out);
  }
  return outcomes;
}

const ScanOutcome& at(const std::vector<ScanOutcome>& outcomes, Time t) { return outcomes.at(t / kSweep); }

TEST(VisVelocityGate, ASlowVisIsRefusedWhileTheLidarHoldsTheLisAndAcceptedOnceTheLisHasBeenBlindLongEnough) {
  const std::vector<ScanOutcome> blind = run(8 * kSec, true);
  // Before it slows the VIS agrees with the IMU (checked at every sweep; no sweep is degenerate, so no factor).
  EXPECT_TRUE(at(blind, 4 * kSec).vis_unused.empty()) << at(blind, 4 * kSec).vis_unused;
  // 0.5 s into the blind stretch: 0.30 m/s off against 0.2 + 0.05 + 0.05 x 0.5 = 0.275 m/s.
  const ScanOutcome& early = at(blind, kBlindFrom + 5 * kSweep);
  EXPECT_FALSE(early.vis_factor);
  EXPECT_NE(early.vis_unused.find("velocity differs from the IMU's prediction by 0.30 m/s"), std::string::npos)
      << early.vis_unused;
  // 1.0 s in the limit reaches the difference (0.25 + 0.05 x 1.0 = 0.30 m/s), and the VIS's motion is a factor.
  Time first_factor = 0;
  for (const ScanOutcome& o : blind)
    if (o.vis_factor && first_factor == 0) first_factor = o.t;
  EXPECT_GE(first_factor, kBlindFrom + 9 * kSweep);
  EXPECT_LE(first_factor, kBlindFrom + 11 * kSweep);

  // The lidar holding the LIS all along: the slow VIS is refused at every sweep after it slowed.
  const std::vector<ScanOutcome> held = run(8 * kSec, false);
  for (Time t = kBlindFrom + 2 * kSweep; t <= 8 * kSec; t += kSweep) {
    EXPECT_FALSE(at(held, t).vis_factor);
    EXPECT_NE(at(held, t).vis_unused.find("velocity differs"), std::string::npos) << toSeconds(t) << " s";
  }
}

}  // namespace
}  // namespace drover::pipeline
