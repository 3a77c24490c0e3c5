// kitti05-replay: the KITTI 05 ground truth in a z-up world, driven through a procedural town.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/trajectory_io.hpp"
#include "sim/scenario.hpp"
#include "sim/scenario_probe.hpp"
#include "support/shared_data.hpp"

namespace drover::sim {
namespace {

using Eigen::Vector3d;
using G = CourseGeometry;
using probe::nearestObstacle;
constexpr Time kKittiTenHz = 100'000'000;

bool hasSegment(const Scenario& s, Condition c) {
  return std::any_of(s.segments.begin(), s.segments.end(), [&](const Segment& g) { return g.condition == c; });
}

TEST(KittiCameraToZupBody, MapsCameraForwardToBodyXAndLevelsATiltedDrive) {
  // A circle of radius 20 m driven on a plane tilted by 2 deg about the camera's x axis, camera looking along the
  // tangent: after conversion the drive is level, distances are kept and the body's x axis points along the motion.
  Trajectory cam;
  const double tilt = 2.0 * std::numbers::pi / 180;
  const Eigen::Matrix3d Rtilt = Eigen::AngleAxisd(tilt, Vector3d::UnitX()).toRotationMatrix();
  for (int i = 0; i < 40; ++i) {
    const double a = 2 * std::numbers::pi * i / 40;
    StampedPose p;
    p.t = i * kKittiTenHz;
    // In the level camera world (y down): position on a circle in x-z, forward (z) along the tangent.
    const Vector3d pos(20 * (1 - std::cos(a)), 0.0, 20 * std::sin(a));
    const Eigen::Matrix3d R = Eigen::AngleAxisd(a, Vector3d::UnitY()).toRotationMatrix();
    p.T_world_body.linear() = Rtilt * R;
    p.T_world_body.translation() = Rtilt * pos;
    cam.push_back(p);
  }
  const Trajectory body = kittiCameraToZupBody(cam);
  ASSERT_EQ(body.size(), cam.size());
  for (std::size_t i = 0; i < body.size(); ++i) {
    EXPECT_EQ(body[i].t, cam[i].t);
    EXPECT_NEAR(body[i].T_world_body.translation().z(), body[0].T_world_body.translation().z(), 1e-9);
    EXPECT_NEAR(body[i].T_world_body.linear().col(2).z(), 1.0, 1e-9);  // body z up
    if (i == 0) continue;
    EXPECT_NEAR((body[i].T_world_body.translation() - body[i - 1].T_world_body.translation()).norm(),
                (cam[i].T_world_body.translation() - cam[i - 1].T_world_body.translation()).norm(), 1e-9);
  }
  // Forward (camera z) is the body x axis: at the start the motion is along it.
  const Vector3d step = body[1].T_world_body.translation() - body[0].T_world_body.translation();
  EXPECT_GT(step.normalized().dot(body[0].T_world_body.linear().col(0)), 0.99);
}

class KittiReplay : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const auto poses = test::sharedData("kitti/poses/05.txt");
    const auto times = test::sharedData("kitti/sequences/05/times.txt");
    if (!std::filesystem::exists(poses) || !std::filesystem::exists(times)) return;
    ground_truth_ = new Trajectory(io::readKitti(poses.string(), times.string()));
    ScenarioOptions o;
    o.kitti05_ground_truth = ground_truth_;
    scenario_ = new Scenario(makeScenario("kitti05-replay", o));
  }
  static void TearDownTestSuite() {
    delete scenario_;
    delete ground_truth_;
    scenario_ = nullptr, ground_truth_ = nullptr;
  }
  void SetUp() override { DROVER_REQUIRE_SHARED(test::sharedData("kitti/poses/05.txt")); }
  static Trajectory* ground_truth_;
  static Scenario* scenario_;
};
Trajectory* KittiReplay::ground_truth_ = nullptr;
Scenario* KittiReplay::scenario_ = nullptr;

TEST_F(KittiReplay, DrivesTheGroundTruthPathWithinFiveCentimetresAndOnePercentOfItsLength) {
  ASSERT_NE(scenario_, nullptr);
  const Trajectory body = kittiCameraToZupBody(*ground_truth_);
  double gt_length = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < body.size(); ++i) {
    if (i > 0) gt_length += (body[i].T_world_body.translation() - body[i - 1].T_world_body.translation()).norm();
    const Time t = body[i].t - body.front().t;
    worst = std::max(worst, (scenario_->trajectory->pose(t).translation() - body[i].T_world_body.translation()).norm());
  }
  EXPECT_GT(gt_length, 2000.0);  // KITTI 05: 2.2 km
  EXPECT_NEAR(scenario_->trajectory->pathLength(), gt_length, 0.01 * gt_length);
  EXPECT_LT(worst, 0.05);
  EXPECT_TRUE(scenario_->closes_loop);  // 05 revisits its streets
  EXPECT_TRUE(hasSegment(*scenario_, Condition::kOverlap));
}

TEST_F(KittiReplay, DurationCutsTheDriveButCannotExtendIt) {
  ASSERT_NE(scenario_, nullptr);
  ScenarioOptions o;
  o.kitti05_ground_truth = ground_truth_;
  o.duration_s = 60.0;
  const Scenario cut = makeScenario("kitti05-replay", o);
  EXPECT_EQ(cut.trajectory->endTime(), 60 * kNanosPerSecond);
  EXPECT_LT((cut.trajectory->pose(30 * kNanosPerSecond).translation() -
             scenario_->trajectory->pose(30 * kNanosPerSecond).translation())
                .norm(),
            1e-6);
  o.duration_s = 400.0;  // the car is at speed when the sequence ends (~10 m/s): no way to go on
  EXPECT_THROW(makeScenario("kitti05-replay", o), std::invalid_argument);
}

TEST_F(KittiReplay, KeepsEveryTownPrimitiveTwoMetresFromThePath) {
  ASSERT_NE(scenario_, nullptr);
  EXPECT_GT(scenario_->world.primitiveCount(), 500u);
  EXPECT_LT(scenario_->world.primitiveCount(), 5000u);
  const SplineTrajectory& traj = *scenario_->trajectory;
  for (Time t = traj.startTime(); t <= traj.endTime(); t += 5 * kKittiTenHz)
    ASSERT_GE(nearestObstacle(*scenario_, t, G::kTownClearance), G::kTownClearance) << "at t = " << toSeconds(t);
  // The road lies the camera height below.
  const Vector3d o = traj.pose(traj.startTime()).translation();
  const auto road = scenario_->world.intersect({o, -Vector3d::UnitZ()});
  ASSERT_TRUE(road.has_value());
  EXPECT_NEAR(road->distance, G::kKittiCameraHeight, 0.05);
  EXPECT_EQ(road->material->texture, Texture::kAsphalt);
}

}  // namespace
}  // namespace drover::sim
