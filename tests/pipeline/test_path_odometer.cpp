// The LIS's path length over time (pipeline::PathOdometer), which the VIS's keyframe gate asks how far the robot
// went since a keyframe: exact on a path at constant speed, linear between states, blind to a loop's correction.
#include <gtest/gtest.h>

#include "pipeline/path_odometer.hpp"
#include "support/units.hpp"

namespace drover::pipeline {
namespace {

using ::drover::test::kSec;

TEST(PathOdometer, GivesThePathLengthBetweenTwoTimesLinearBetweenTheStates) {
  PathOdometer o;
  for (int k = 0; k <= 20; ++k)  // 1.2 m/s along a diagonal, 10 Hz states
    o.add(k * kSec / 10, Eigen::Vector3d(0.6, 0.0, 0.8) * (1.2 * 0.1 * k));
  EXPECT_NEAR(o.between(kSec / 4, 1'050'000'000), 1.2 * 0.8, 1e-12);
  EXPECT_NEAR(o.between(0, 2 * kSec), 2.4, 1e-12);
  EXPECT_EQ(o.between(kSec, kSec / 2), 0.0) << "an empty interval";
  EXPECT_NEAR(o.between(-5 * kSec, kSec / 10), 0.12, 1e-12) << "no motion counted before the first state";
  EXPECT_NEAR(o.between(19 * kSec / 10, 9 * kSec), 0.12, 1e-12) << "nor after the newest";
  EXPECT_EQ(o.newest(), 2 * kSec);
}

TEST(PathOdometer, StandingStillAddsNothingAndALoopCorrectionIsNoMotion) {
  PathOdometer o;
  for (int k = 0; k <= 30; ++k) o.add(k * kSec / 10, Eigen::Vector3d(4.0, -2.0, 0.5));  // 3 s standing
  EXPECT_EQ(o.between(0, 3 * kSec), 0.0);
  Eigen::Isometry3d T_new_old = Eigen::Isometry3d::Identity();  // the loop moves the world 5 m and turns it
  T_new_old.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_new_old.translation() = Eigen::Vector3d(5.0, 1.0, 0.0);
  o.moveWorld(T_new_old);
  o.add(31 * kSec / 10, T_new_old * Eigen::Vector3d(4.1, -2.0, 0.5));  // then 0.1 m in the corrected world
  EXPECT_NEAR(o.between(0, 4 * kSec), 0.1, 1e-12);
  o.add(31 * kSec / 10, Eigen::Vector3d(100, 0, 0));  // not after the newest: ignored
  EXPECT_NEAR(o.between(0, 4 * kSec), 0.1, 1e-12);
}

}  // namespace
}  // namespace drover::pipeline
