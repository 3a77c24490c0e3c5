// RPE as evo_rpe with consecutive pairs, on hand-computed examples.
#include <gtest/gtest.h>

#include <numbers>
#include <stdexcept>

#include "eval/rpe.hpp"
#include "eval_fixtures.hpp"

namespace drover::eval {
namespace {

using test::pose;

Trajectory alongX(const std::vector<double>& xs) {
  Trajectory t;
  for (std::size_t i = 0; i < xs.size(); ++i)
    t.push_back({static_cast<Time>(i) * 100'000'000, pose(Eigen::Vector3d::Zero(), Eigen::Vector3d(xs[i], 0, 0))});
  return t;
}

TEST(RpePairs, FramesTakeEveryDeltaThIndexAndPairThemConsecutively) {
  EXPECT_EQ(pairsByIndex(7, 3), (IdPairs{{0, 3}, {3, 6}}));
  EXPECT_EQ(pairsByIndex(6, 3), (IdPairs{{0, 3}}));  // ids 0, 3 (6 is past the end)
  EXPECT_EQ(pairsByIndex(3, 1), (IdPairs{{0, 1}, {1, 2}}));
  EXPECT_TRUE(pairsByIndex(3, 3).empty());
  EXPECT_THROW(pairsByIndex(3, 0), std::invalid_argument);
}

TEST(RpePairs, MetersStartAtTheFirstPoseWhereThePathReachesDeltaAndResetTheAccumulator) {
  // x = 0, 0.4, 1.0, 1.3, 2.5, 2.6, 3.7 with delta 1 m: the path reaches 1.0 at pose 2 (id, reset; 0.4 + 0.6 is
  // exactly 1.0 in double, and >= keeps it), then
  // 0.3 + 1.2 = 1.5 at pose 4 (id, reset), then 0.1 + 1.1 = 1.2 at pose 6 -> ids 2, 4, 6.
  const Trajectory t = alongX({0, 0.4, 1.0, 1.3, 2.5, 2.6, 3.7});
  EXPECT_EQ(pairsByPath(t, 1.0), (IdPairs{{2, 4}, {4, 6}}));
  // delta 3 m is reached at the last pose only: one id, no pair.
  EXPECT_TRUE(pairsByPath(t, 3.0).empty());
  EXPECT_THROW(pairsByPath(t, 0.0), std::invalid_argument);
}

// Reference along x at 0..4 m with identity rotation. The estimate is rotated by 90 deg yaw and runs along y,
// so its relative motion is the reference's, except pose 4: 0.2 m too far and 0.1 rad extra yaw.
Trajectory rpeReference() { return alongX({0, 1, 2, 3, 4}); }
Trajectory rpeEstimate() {
  const double q = std::numbers::pi / 2;
  Trajectory t;
  const double ys[] = {0, 1, 2, 3, 4.2};
  for (int i = 0; i < 5; ++i)
    t.push_back({static_cast<Time>(i) * 100'000'000,
                 pose(Eigen::Vector3d(0, 0, i == 4 ? q + 0.1 : q), Eigen::Vector3d(0, ys[i], 0))});
  return t;
}

TEST(Rpe, HandComputedErrorsForDeltaTwoFrames) {
  // Pairs (0, 2), (2, 4). Pair (0, 2): P_rel = [I | (2, 0, 0)] = Q_rel -> E = I.
  // Pair (2, 4): Q_rel = [I | (2, 0, 0)], P_rel = [Rz(0.1) | Rz(-90)(0, 2.2, 0)] = [Rz(0.1) | (2.2, 0, 0)],
  // E = Q_rel^-1 P_rel = [Rz(0.1) | (0.2, 0, 0)].
  const Trajectory ref = rpeReference(), est = rpeEstimate();
  RpeOptions o;
  o.delta = 2;
  o.unit = DeltaUnit::kFrames;
  const RpeResult t = computeRpe(ref, est, o);
  EXPECT_EQ(t.id_pairs, (IdPairs{{0, 2}, {2, 4}}));
  ASSERT_EQ(t.errors.size(), 2u);
  EXPECT_NEAR(t.errors[0], 0.0, 1e-12);
  EXPECT_NEAR(t.errors[1], 0.2, 1e-12);
  EXPECT_EQ(t.times, (std::vector<Time>{200'000'000, 400'000'000}));
  o.relation = PoseRelation::kAngleDeg;
  const RpeResult a = computeRpe(ref, est, o);
  EXPECT_NEAR(a.errors[0], 0.0, 1e-9);
  EXPECT_NEAR(a.errors[1], 0.1 * 180.0 / std::numbers::pi, 1e-9);
  o.relation = PoseRelation::kFull;
  // |E - I|_F^2 = |Rz(0.1) - I|_F^2 + 0.2^2 = 4 - 4 cos(0.1) + 0.04.
  EXPECT_NEAR(computeRpe(ref, est, o).errors[1], std::sqrt(4.0 - 4.0 * std::cos(0.1) + 0.04), 1e-12);
  o.relation = PoseRelation::kRotation;
  EXPECT_NEAR(computeRpe(ref, est, o).errors[1], std::sqrt(4.0 - 4.0 * std::cos(0.1)), 1e-12);
}

TEST(Rpe, MeterPairsComeFromTheEstimatePathLikeEvoUnlessAskedForTheReference) {
  // Reference x = 0, 0.4, 1.0, 1.3, 2.5, 2.6, 3.7 -> ids 2, 4, 6 (see above). The estimate is 3x as long:
  // 0, 1.2, 3.0, 3.9, 7.5, 7.8, 11.1 -> path 1.2 at pose 1, 1.8 at 2, 0.9 + 3.6 at 4, 0.3 + 3.3 at 6 -> ids 1, 2, 4, 6.
  const std::vector<double> xs{0, 0.4, 1.0, 1.3, 2.5, 2.6, 3.7};
  std::vector<double> xs3;
  for (const double x : xs) xs3.push_back(3 * x);
  RpeOptions o;
  o.delta = 1.0;
  o.unit = DeltaUnit::kMeters;
  EXPECT_EQ(computeRpe(alongX(xs), alongX(xs3), o).id_pairs, (IdPairs{{1, 2}, {2, 4}, {4, 6}}));
  o.pairs_from_reference = true;
  const RpeResult r = computeRpe(alongX(xs), alongX(xs3), o);
  EXPECT_EQ(r.id_pairs, (IdPairs{{2, 4}, {4, 6}}));
  // Pair (2, 4): reference moves 1.5 m, estimate 4.5 m -> 3.0 m; pair (4, 6): 1.2 vs 3.6 -> 2.4 m.
  EXPECT_NEAR(r.errors[0], 3.0, 1e-12);
  EXPECT_NEAR(r.errors[1], 2.4, 1e-12);
}

TEST(Rpe, Se3AlignmentDoesNotChangeRelativeErrors) {
  // A rigid transform of the whole estimate cancels in P_i^-1 P_j.
  const Trajectory ref = test::referenceTrajectory(40);
  Trajectory est = ref;
  for (std::size_t i = 0; i < est.size(); ++i)
    est[i].T_world_body = pose(Eigen::Vector3d(0.2, 0.1, -1.0), Eigen::Vector3d(5, 6, 7)) * est[i].T_world_body *
                          pose(Eigen::Vector3d(0.01 * (i % 3), 0, 0), Eigen::Vector3d(0.02 * (i % 4), 0, 0));
  RpeOptions o;
  o.delta = 3;
  const RpeResult none = computeRpe(ref, est, o);
  o.alignment = Alignment::kSe3;
  const RpeResult se3 = computeRpe(ref, est, o);
  ASSERT_EQ(none.errors.size(), se3.errors.size());
  for (std::size_t k = 0; k < none.errors.size(); ++k) EXPECT_NEAR(none.errors[k], se3.errors[k], 1e-9);
  EXPECT_GT(none.stats.max, 0.01);
}

TEST(Rpe, RejectsBadDeltasAndADeltaThatSelectsNoPair) {
  const Trajectory ref = rpeReference(), est = rpeEstimate();
  RpeOptions o;
  o.delta = 0;
  EXPECT_THROW(computeRpe(ref, est, o), std::invalid_argument);
  o.delta = 1.5;
  EXPECT_THROW(computeRpe(ref, est, o), std::invalid_argument);
  o.delta = 5;  // ids 0 only
  EXPECT_THROW(computeRpe(ref, est, o), std::invalid_argument);
  o.unit = DeltaUnit::kMeters;
  o.delta = -1.0;
  EXPECT_THROW(computeRpe(ref, est, o), std::invalid_argument);
  o.delta = 100.0;
  EXPECT_THROW(computeRpe(ref, est, o), std::invalid_argument);
}

}  // namespace
}  // namespace drover::eval
