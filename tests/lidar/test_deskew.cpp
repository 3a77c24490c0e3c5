// Deskew: a sweep simulated while turning and driving, compensated with the exact motion, lands on the world's
// surfaces as a static lidar at the sweep start would see them; partial and no compensation leave known errors.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "geometry/se3.hpp"
#include "lidar/deskew.hpp"
#include "sim/lidar_model.hpp"
#include "support/units.hpp"

namespace drover::lidar {
namespace {

using ::drover::test::kSec;
using ::drover::test::kDeg;

sim::SplineTrajectory trajectoryOf(const std::function<sim::PathSample(double)>& f) {
  std::vector<sim::PathSample> samples;
  for (int k = 0; k <= 20; ++k) {
    sim::PathSample s = f(0.1 * k);
    s.t = k * kSec / 10;
    samples.push_back(s);
  }
  return sim::SplineTrajectory(samples);
}

// A closed 8 x 6 x 3 m room, floor at z = 0.
sim::World room() {
  sim::World w;
  sim::Box box;
  box.T_world_box.translation() = Eigen::Vector3d(0, 0, 1.5);
  box.half_extents = Eigen::Vector3d(4, 3, 1.5);
  w.addBox(box, sim::Material{});
  w.build();
  return w;
}

Eigen::Isometry3d lidarOnBody() {
  Eigen::Isometry3d T_body_lidar = Eigen::Isometry3d::Identity();
  T_body_lidar.translation() = Eigen::Vector3d(0.2, -0.1, 0.4);
  T_body_lidar.linear() = Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T_body_lidar;
}

// Turning at 90 deg/s while driving at 1 m/s along world x.
const sim::SplineTrajectory& turningAndDriving() {
  static const sim::SplineTrajectory trajectory = trajectoryOf([](double t) {
    sim::PathSample s;
    s.p_world = Eigen::Vector3d(-1.0 + t, 0.3, 1.0);
    s.yaw = std::numbers::pi / 2 * t;
    return s;
  });
  return trajectory;
}

LidarScan sweepAlong(const sim::World& world, const sim::SplineTrajectory& trajectory, Time t0) {
  sim::LidarModelConfig c = sim::LidarModelConfig::forModel("vlp16");
  c.noise = false;
  return sim::simulateSweep(world, trajectory, lidarOnBody(), t0, c, 1, 0);
}

// T_start_lidar(t) from the ground-truth trajectory.
SweepMotion exactMotion(const sim::SplineTrajectory& trajectory, Time t0) {
  const Eigen::Isometry3d T_start_world = (trajectory.pose(t0) * lidarOnBody()).inverse();
  return [&trajectory, t0, T_start_world](double t) {
    return T_start_world * trajectory.pose(t0 + fromSeconds(t)) * lidarOnBody();
  };
}

// Largest disagreement [m] between each point's range and the range a static lidar at T_world_start measures in its
// direction (ray cast into the world).
double worstRangeError(const sim::World& world, const Eigen::Isometry3d& T_world_start, const LidarScan& scan) {
  double worst = 0;
  for (const LidarPoint& p : scan.points) {
    const Eigen::Vector3d p_start(p.x, p.y, p.z);
    const sim::Ray ray{T_world_start.translation(), T_world_start.linear() * p_start.normalized()};
    const auto hit = world.intersect(ray);
    worst = std::max(worst, hit ? std::abs(hit->distance - p_start.norm()) : 1e9);
  }
  return worst;
}

double errorAfter(DeskewMode mode, const LidarScan& scan, const SweepMotion& motion, const sim::World& world,
                  const Eigen::Isometry3d& T_world_start) {
  DeskewerConfig config;
  config.mode = mode;
  const DeskewResult result = Deskewer(config).deskew(scan, motion);
  EXPECT_EQ(result.status, DeskewStatus::kOk);
  return worstRangeError(world, T_world_start, result.scan);
}

TEST(Deskew, ExactMotionPutsEveryPointOnTheWorldAsSeenFromTheSweepStartToAMillimetre) {
  const sim::World world = room();
  const Time t0 = kSec / 2;
  const LidarScan scan = sweepAlong(world, turningAndDriving(), t0);
  ASSERT_EQ(scan.points.size(), 16u * 1800u);
  const Eigen::Isometry3d T_world_start = turningAndDriving().pose(t0) * lidarOnBody();
  const SweepMotion motion = exactMotion(turningAndDriving(), t0);
  const double full = errorAfter(DeskewMode::kFull, scan, motion, world, T_world_start);
  const double none = errorAfter(DeskewMode::kNone, scan, motion, world, T_world_start);
  const double rotation = errorAfter(DeskewMode::kRotation, scan, motion, world, T_world_start);
  EXPECT_LT(full, 1e-3);
  EXPECT_GT(none, 0.3);          // 9 deg of turn over the sweep at 2-5 m range
  EXPECT_GT(rotation, 0.03);     // 0.1 m of travel left uncompensated
  EXPECT_LT(rotation, 0.5 * none);
}

TEST(Deskew, TranslationOnlyCompensatesAPureTranslationExactly) {
  const sim::World world = room();
  const sim::SplineTrajectory driving = trajectoryOf([](double t) {
    sim::PathSample s;
    s.p_world = Eigen::Vector3d(-1.0 + 2.0 * t, 0.5 * t, 1.0);
    return s;
  });
  const Time t0 = kSec / 2;
  const LidarScan scan = sweepAlong(world, driving, t0);
  const Eigen::Isometry3d T_world_start = driving.pose(t0) * lidarOnBody();
  const SweepMotion motion = exactMotion(driving, t0);
  EXPECT_LT(errorAfter(DeskewMode::kTranslation, scan, motion, world, T_world_start), 1e-3);
  EXPECT_GT(errorAfter(DeskewMode::kNone, scan, motion, world, T_world_start), 0.1);
}

// A constant body twist (driving a circle at constant speed and yaw rate) is what the constant-velocity model
// assumes: the relative pose over one period is then enough to deskew exactly.
TEST(Deskew, ConstantVelocityModelUndistortsAConstantTwistSweep) {
  const double v = 2.0, omega = std::numbers::pi / 2, radius = v / omega;  // [m/s], [rad/s], [m]
  const sim::SplineTrajectory circle = trajectoryOf([&](double t) {
    sim::PathSample s;
    s.p_world = Eigen::Vector3d(-0.5 + radius * std::sin(omega * t), -1 + radius * (1 - std::cos(omega * t)), 1.0);
    s.yaw = omega * t;
    return s;
  });
  const sim::World world = room();
  const Time t0 = kSec / 2;
  const double period = 0.1;
  const LidarScan scan = sweepAlong(world, circle, t0);
  const Eigen::Isometry3d T_world_start = circle.pose(t0) * lidarOnBody();
  const Eigen::Isometry3d T_start_end = T_world_start.inverse() * circle.pose(t0 + fromSeconds(period)) * lidarOnBody();
  const SweepMotion model = constantVelocityMotion(T_start_end, period);
  EXPECT_TRUE(model(0.0).isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(model(period).isApprox(T_start_end, 1e-9));
  EXPECT_LT(errorAfter(DeskewMode::kFull, scan, model, world, T_world_start), 1e-3);
  EXPECT_GT(errorAfter(DeskewMode::kNone, scan, model, world, T_world_start), 0.2);
}

TEST(Deskew, KeepsRingTimeIntensityAndFlags) {
  const LidarScan scan = sweepAlong(room(), turningAndDriving(), kSec / 2);
  const DeskewResult result = Deskewer().deskew(scan, exactMotion(turningAndDriving(), kSec / 2));
  ASSERT_EQ(result.scan.points.size(), scan.points.size());
  EXPECT_EQ(result.scan.t, scan.t);
  EXPECT_EQ(result.scan.t_end, scan.t_end);
  EXPECT_TRUE(result.scan.has_time && result.scan.has_ring);
  EXPECT_NEAR(result.max_time_offset, toSeconds(scan.t_end - scan.t), 1e-6);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    ASSERT_EQ(result.scan.points[i].ring, scan.points[i].ring);
    ASSERT_EQ(result.scan.points[i].time_offset, scan.points[i].time_offset);
    ASSERT_EQ(result.scan.points[i].intensity, scan.points[i].intensity);
  }
}

TEST(Deskew, DegenerateScansAndMissingInputsAreReported) {
  const SweepMotion identity = [](double) { return Eigen::Isometry3d::Identity(); };
  LidarScan scan;
  scan.has_time = true;
  EXPECT_EQ(Deskewer().deskew(scan, identity).status, DeskewStatus::kEmpty);
  LidarPoint p;
  p.x = 3;
  scan.points = {p, p};
  // All at time 0: only T_start_lidar(0) applies.
  const SweepMotion shifted = [](double) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation().x() = 1;
    return T;
  };
  const DeskewResult same_time = Deskewer().deskew(scan, shifted);
  EXPECT_EQ(same_time.status, DeskewStatus::kNoTimeSpread);
  EXPECT_FLOAT_EQ(same_time.scan.points[1].x, 4.0f);
  EXPECT_THROW(Deskewer().deskew(scan, SweepMotion{}), std::invalid_argument);
  scan.has_time = false;
  EXPECT_THROW(Deskewer().deskew(scan, identity), std::invalid_argument);
  DeskewerConfig bad;
  bad.time_bins = 0;
  EXPECT_NE(bad.validate().find("time_bins"), std::string::npos);
  EXPECT_THROW(Deskewer{bad}, std::invalid_argument);
  EXPECT_THROW(constantVelocityMotion(Eigen::Isometry3d::Identity(), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace drover::lidar
