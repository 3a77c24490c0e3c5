// The 4-DoF pose graph (PoseGraphConfig::yaw_only_rotation, backend::WorldYawManifold): nodes turn about the world
// vertical only, so a loop whose relative roll or pitch is off cannot tilt a gravity-aligned map (VINS-Mono, T-RO
// 2018, Sec. VIII-B). Known answers on a helix whose odometry drifted in yaw and position only, as an IMU-aided
// odometry does.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "backend/pose_graph.hpp"
#include "backend/quaternion_manifold.hpp"
#include "geometry/so3.hpp"
#include "pose_graph_test_util.hpp"
#include "support/units.hpp"

namespace drover::backend {
namespace {

using ::drover::test::kPi;

Eigen::Quaterniond someRotation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  return Eigen::Quaterniond(geometry::expSO3(Eigen::Vector3d(0.4 * u(rng), 0.4 * u(rng), 3 * u(rng)))).normalized();
}

// The world vertical seen from the body: what gravity fixes (roll and pitch), whatever the yaw.
Eigen::Vector3d tilt(const Eigen::Matrix3d& R_world_body) { return R_world_body.transpose() * Eigen::Vector3d::UnitZ(); }

TEST(WorldYawManifold, PlusTurnsAboutTheWorldVerticalMinusInvertsItAndTheTiltNeverChanges) {
  std::mt19937 rng(5);
  const WorldYawManifold m;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Quaterniond q = someRotation(rng);
    const double d = std::uniform_real_distribution<double>(-3, 3)(rng);
    Eigen::Quaterniond out;
    ASSERT_TRUE(m.Plus(q.coeffs().data(), &d, out.coeffs().data()));
    const Eigen::Matrix3d expected = Eigen::AngleAxisd(d, Eigen::Vector3d::UnitZ()).toRotationMatrix() * q;
    EXPECT_LT((out.toRotationMatrix() - expected).norm(), 1e-12);
    EXPECT_LT((tilt(out.toRotationMatrix()) - tilt(q.toRotationMatrix())).norm(), 1e-12);
    double back = 0;
    ASSERT_TRUE(m.Minus(out.coeffs().data(), q.coeffs().data(), &back));
    EXPECT_NEAR(back, d, 1e-12);
  }
}

TEST(WorldYawManifold, PlusAndMinusJacobiansMatchFiniteDifferencesAndInvertEachOther) {
  std::mt19937 rng(6);
  const WorldYawManifold m;
  for (int i = 0; i < 10; ++i) {
    const Eigen::Quaterniond q = someRotation(rng);
    Eigen::Vector4d J, Jm;
    ASSERT_TRUE(m.PlusJacobian(q.coeffs().data(), J.data()));
    ASSERT_TRUE(m.MinusJacobian(q.coeffs().data(), Jm.data()));
    const double h = 1e-6;
    Eigen::Quaterniond a, b;
    const double plus = h, minus = -h;
    m.Plus(q.coeffs().data(), &plus, a.coeffs().data());
    m.Plus(q.coeffs().data(), &minus, b.coeffs().data());
    EXPECT_LT((J - (a.coeffs() - b.coeffs()) / (2 * h)).norm(), 1e-8);
    EXPECT_NEAR(Jm.dot(J), 1.0, 1e-12);
  }
}

using test::helix;
using test::information;

struct Solved {
  double worst_tilt_change = 0;  // [rad] largest change of a node's tilt (the vertical in its frame) in the solve
  double end_error = 0;          // [m] last node's position error after it
  double end_error_before = 0;   // [m] before it
};

// The odometry drifted 0.3 deg of yaw and 2 cm along x per step (a world-frame drift, so every node keeps its true
// roll and pitch), and its edges say so; one loop from the last node to the first is measured from the truth, but
// with 1 deg of roll error (the relative tilt a lidar match gets slightly wrong).
Solved solveDriftedHelix(bool yaw_only) {
  const std::vector<Eigen::Isometry3d> truth = helix(40);
  PoseGraphConfig config;
  config.yaw_only_rotation = yaw_only;
  PoseGraph graph(config);
  std::vector<Eigen::Isometry3d> drifted;
  for (int k = 0; k < static_cast<int>(truth.size()); ++k) {
    Eigen::Isometry3d D = Eigen::Isometry3d::Identity();
    D.linear() = Eigen::AngleAxisd(0.3 * kPi / 180 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    D.translation() << 0.02 * k, 0, 0;
    drifted.push_back(D * truth[k]);
    graph.addNode(k, drifted.back());
    if (k > 0)
      graph.addEdge(k - 1, k, drifted[k - 1].inverse() * drifted[k], information(0.02, 0.002), EdgeKind::kOdometry);
  }
  Eigen::Isometry3d loop = truth.back().inverse() * truth.front();
  loop.linear() = loop.linear() * Eigen::AngleAxisd(kPi / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const int last = static_cast<int>(truth.size()) - 1;
  graph.addEdge(last, 0, loop, information(0.01, 0.002), EdgeKind::kLoop);
  Solved s;
  s.end_error_before = (graph.pose(last).translation() - truth.back().translation()).norm();
  const PoseGraphResult r = graph.optimize();
  EXPECT_TRUE(r.usable) << r.reason;
  for (int k = 0; k <= last; ++k)
    s.worst_tilt_change =  // the chord between unit vectors: the angle, to first order
        std::max(s.worst_tilt_change, (tilt(graph.pose(k).linear()) - tilt(drifted[k].linear())).norm());
  s.end_error = (graph.pose(last).translation() - truth.back().translation()).norm();
  return s;
}

TEST(PoseGraph, YawOnlyNodesCloseTheLoopInPositionAndYawAndKeepEveryNodesRollAndPitch) {
  const Solved four = solveDriftedHelix(true);
  EXPECT_LT(four.worst_tilt_change, 1e-12);
  EXPECT_GT(four.end_error_before, 0.8);
  EXPECT_LT(four.end_error, 0.1 * four.end_error_before);
  // The full 6-DoF graph spreads the loop's roll error over the nodes and tilts them.
  const Solved six = solveDriftedHelix(false);
  EXPECT_GT(six.worst_tilt_change, 0.2 * kPi / 180);
  EXPECT_LT(six.end_error, 0.1 * six.end_error_before);
}

}  // namespace
}  // namespace drover::backend
