// posesAtTimes: one pose per requested time, exact where the trajectory has one, on the screw motion between or
// beyond its poses otherwise -- checked on a constant-twist trajectory, where both are exact.
#include <gtest/gtest.h>

#include <stdexcept>

#include "geometry/se3.hpp"
#include "geometry/trajectory_fill.hpp"

namespace drover::geometry {
namespace {

// Constant twist: 1 m/s forward while yawing at 0.2 rad/s, so T(t) = Exp(t xi) exactly.
Eigen::Isometry3d truth(Time t) {
  Vector6d xi;
  xi << 1.0, 0.0, 0.0, 0.0, 0.0, 0.2;
  return expSE3(toSeconds(t) * xi);
}

Trajectory sampled(const std::vector<Time>& times) {
  Trajectory tr;
  for (Time t : times) tr.push_back({t, truth(t)});
  return tr;
}

void expectPose(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  EXPECT_LT((a.translation() - b.translation()).norm(), 1e-9);
  EXPECT_LT(Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle(), 1e-9);
}

TEST(TrajectoryFill, TimesWithAPoseGetItUnchangedAndAreMarkedEstimated) {
  const Trajectory tr = sampled({0, 100'000'000, 200'000'000});
  const std::vector<FilledPose> f = posesAtTimes(tr, {0, 100'000'000, 200'000'000});
  ASSERT_EQ(f.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(f[i].kind, FillKind::kEstimated);
    EXPECT_EQ(f[i].pose.t, tr[i].t);
    expectPose(f[i].pose.T_world_body, tr[i].T_world_body);
  }
}

TEST(TrajectoryFill, AMissingTimeBetweenTwoPosesIsInterpolatedExactlyOnAConstantTwist) {
  const Trajectory tr = sampled({0, 100'000'000, 300'000'000});
  const std::vector<FilledPose> f = posesAtTimes(tr, {200'000'000, 250'000'000});
  EXPECT_EQ(f[0].kind, FillKind::kInterpolated);
  expectPose(f[0].pose.T_world_body, truth(200'000'000));
  expectPose(f[1].pose.T_world_body, truth(250'000'000));
}

TEST(TrajectoryFill, TimesBeforeTheFirstAndAfterTheLastPoseAreExtrapolatedAtConstantVelocity) {
  const Trajectory tr = sampled({100'000'000, 200'000'000, 300'000'000});
  const std::vector<FilledPose> f = posesAtTimes(tr, {0, 500'000'000});
  EXPECT_EQ(f[0].kind, FillKind::kExtrapolated);
  EXPECT_EQ(f[1].kind, FillKind::kExtrapolated);
  expectPose(f[0].pose.T_world_body, truth(0));
  expectPose(f[1].pose.T_world_body, truth(500'000'000));
}

TEST(TrajectoryFill, ASinglePoseIsHeldAtEveryOtherTime) {
  const Trajectory tr = sampled({100'000'000});
  const std::vector<FilledPose> f = posesAtTimes(tr, {0, 100'000'000, 900'000'000});
  EXPECT_EQ(f[0].kind, FillKind::kExtrapolated);
  EXPECT_EQ(f[1].kind, FillKind::kEstimated);
  expectPose(f[2].pose.T_world_body, tr[0].T_world_body);
}

TEST(TrajectoryFill, AnEmptyOrUnorderedTrajectoryIsRejected) {
  EXPECT_THROW(posesAtTimes({}, {0}), std::invalid_argument);
  EXPECT_THROW(posesAtTimes(sampled({200, 100}), {0}), std::invalid_argument);
  EXPECT_THROW(posesAtTimes(sampled({100, 100}), {0}), std::invalid_argument);
}

}  // namespace
}  // namespace drover::geometry
