// mav-room: a MAV's flight in a textured room, EuRoC's Vicon-room class of motion, and the EuRoC rig it is flown
// with (sim::SimulatorConfig::eurocRig()): its IMU in EuRoC's axes, consistent with the ground truth.
#include <gtest/gtest.h>

#include <cmath>

#include "io/sim_dataset.hpp"
#include "sim/scenario.hpp"
#include "sim/simulator.hpp"

namespace drover::sim {
namespace {

constexpr Time kMavTenHz = 100'000'000;

const Scenario& mavRoom() {
  static const Scenario s = makeScenario("mav-room", ScenarioOptions{});
  return s;
}

TEST(MavRoom, HoversStillAtBothEndsAndFliesInsideTheRoomClearOfEveryWall) {
  const Scenario& s = mavRoom();
  const SplineTrajectory& tr = *s.trajectory;
  EXPECT_NEAR(toSeconds(tr.endTime() - tr.startTime()), 100.0, 1e-9);
  EXPECT_LT(tr.at(tr.startTime()).v_world.norm(), 1e-9);
  EXPECT_LT(tr.at(tr.endTime()).v_world.norm(), 1e-9);
  for (Time t = tr.startTime(); t <= tr.startTime() + 2 * kNanosPerSecond; t += kMavTenHz / 10)  // the IMU's rest
    ASSERT_LT(tr.at(t).v_world.norm(), 2e-4) << toSeconds(t);  // the spline's ringing before the motion fades in
  EXPECT_TRUE(s.closes_loop);
  for (Time t = tr.startTime(); t <= tr.endTime(); t += kMavTenHz) {
    const Eigen::Vector3d p = tr.pose(t).translation();
    // the room is [-5, 5] x [-4, 4] x [0, 4] m
    EXPECT_LE(std::abs(p.x()), 3.5) << toSeconds(t);
    EXPECT_LE(std::abs(p.y()), 2.5) << toSeconds(t);
    EXPECT_GE(p.z(), 0.7) << toSeconds(t);
    EXPECT_LE(p.z(), 2.5) << toSeconds(t);
  }
}

// EuRoC V1_01 flies 0.41 m/s on average at ~0.3 rad/s, V1_02 0.91 m/s at ~0.6 rad/s (Burri et al. 2016).
TEST(MavRoom, MovesAsEurocsViconRoomSequencesDoBetweenTheEasyAndTheMediumOne) {
  const SplineTrajectory& tr = *mavRoom().trajectory;
  double speed = 0, rate = 0, max_speed = 0, max_rate = 0, max_acc = 0;
  int n = 0;
  for (Time t = tr.startTime() + 5 * kNanosPerSecond; t <= tr.endTime() - 5 * kNanosPerSecond; t += kMavTenHz, ++n) {
    const BodyState b = tr.at(t);
    speed += b.v_world.norm(), rate += b.omega_body.norm();
    max_speed = std::max(max_speed, b.v_world.norm());
    max_rate = std::max(max_rate, b.omega_body.norm());
    max_acc = std::max(max_acc, b.a_world.norm());
  }
  std::printf("mav-room: mean speed %.2f m/s (max %.2f), mean angular rate %.2f rad/s (max %.2f), max acceleration "
              "%.2f m/s^2, path %.1f m\n",
              speed / n, max_speed, rate / n, max_rate, max_acc, tr.pathLength());
  EXPECT_GT(speed / n, 0.41);
  EXPECT_LT(speed / n, 0.91);
  EXPECT_GT(rate / n, 0.25);
  EXPECT_LT(rate / n, 0.65);
  EXPECT_LT(max_speed, 1.5);
  EXPECT_GT(max_acc, 0.3) << "the visual-inertial initialisation needs acceleration to see the scale";
  EXPECT_LT(max_acc, 2.0);
}

TEST(MavRoom, EveryCameraRayHitsTheRoomSoNoFrameLooksIntoTheSky) {
  const Scenario& s = mavRoom();
  const SimulatorConfig rig = SimulatorConfig::eurocRig();
  const CameraRenderer camera(rig.camera);
  const Eigen::Isometry3d T_body_cam = Eigen::Isometry3d(rig.R_body_imu) * rig.T_imu_cam;
  for (Time t = s.trajectory->startTime(); t <= s.trajectory->endTime(); t += 10 * kMavTenHz) {
    const Eigen::Isometry3d T_world_cam = s.trajectory->pose(t) * T_body_cam;
    for (const auto& [u, v] : {std::pair{0, 0}, {751, 0}, {0, 479}, {751, 479}, {376, 240}}) {
      const Ray ray{T_world_cam.translation(), T_world_cam.linear() * camera.ray(u, v).cast<double>()};
      const std::optional<Hit> hit = s.world.intersect(ray);
      ASSERT_TRUE(hit.has_value()) << toSeconds(t) << " s, pixel " << u << "," << v;
      EXPECT_GT(hit->distance, 0.5) << "a wall too close to track";
    }
  }
}

// The rig's IMU reads in EuRoC's axes (x up, y right, z forward): hovering level it feels +g on x, and its
// noise-free samples carried from the ground truth's state land on the ground truth a second later.
TEST(EurocRig, ItsImuReadsInEurocsAxesAndAgreesWithTheGroundTruthItComesWith) {
  SimulatorConfig rig = SimulatorConfig::eurocRig();
  rig.imu.noise = false;
  rig.enable_camera = false;
  ScenarioOptions o;
  o.duration_s = 12;
  const Scenario s = makeScenario("mav-room", o);
  const Simulator sim(s, rig, 1);
  std::vector<ImuSample> imu;
  sim.run([&](Measurement&& m) { imu.push_back(std::get<ImuSample>(m)); });
  // At rest the body is pitched 0.15 rad down: specific force g (cos 0.15, 0, -sin 0.15) in EuRoC's axes.
  EXPECT_NEAR(imu.front().acc_imu.x(), 9.81 * std::cos(0.15), 1e-9);
  EXPECT_NEAR(imu.front().acc_imu.y(), 0.0, 1e-9);
  EXPECT_NEAR(imu.front().acc_imu.z(), -9.81 * std::sin(0.15), 1e-9);
  const std::vector<io::SimGroundTruthState> truth = sim.groundTruthStates();
  ASSERT_EQ(truth.size(), imu.size());
  // Euler integration of 1 s of 200 Hz samples from the truth at 8 s (moving, turning): within 1 cm / 1 mrad.
  const std::size_t k0 = 8 * 200;
  Eigen::Matrix3d R = truth[k0].T_world_imu.linear();
  Eigen::Vector3d p = truth[k0].T_world_imu.translation(), v = R * truth[k0].v_imu;
  const Eigen::Vector3d g(0, 0, -9.81);
  for (std::size_t k = k0; k < k0 + 200; ++k) {
    const double dt = 0.005;
    const Eigen::Vector3d w = 0.5 * (imu[k].omega_imu + imu[k + 1].omega_imu);
    const Eigen::Matrix3d R1 = R * Eigen::AngleAxisd(w.norm() * dt, w.normalized()).toRotationMatrix();
    const Eigen::Vector3d a = 0.5 * (R * imu[k].acc_imu + R1 * imu[k + 1].acc_imu) + g;
    p += v * dt + 0.5 * a * dt * dt;
    v += a * dt;
    R = R1;
  }
  EXPECT_LT((p - truth[k0 + 200].T_world_imu.translation()).norm(), 0.01);
  EXPECT_LT(Eigen::AngleAxisd(R.transpose() * truth[k0 + 200].T_world_imu.linear()).angle(), 1e-3);
  EXPECT_TRUE(sim.calibration().T_imu_cam.isApprox(rig.T_imu_cam));
  EXPECT_EQ(sim.calibration().camera.width, 752);
}

}  // namespace
}  // namespace drover::sim
