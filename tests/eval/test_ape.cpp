// APE with closed-form answers. The estimate is built from the reference as
//   est_i = T * [R_ref,i R_err,i | t_ref,i + o_i]
// where reference poses come in pairs with equal positions and the offsets are o_2k = +v_k, o_2k+1 = -v_k. Then
// the offsets have zero mean and no cross-covariance with the reference positions, so the Umeyama SE(3) alignment
// is exactly T^-1, and E_i = [R_err,i | R_ref,i^T o_i]:
//   trans = |v_k|,  rot = |R_err - I|_F = 2 sqrt(2) sin(theta/2),  angle = theta,  full = sqrt(rot^2 + |v_k|^2).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "eval/ape.hpp"
#include "eval_fixtures.hpp"

namespace drover::eval {
namespace {

using test::pose;

constexpr int kPairs = 20;
constexpr Time kEstClockLag = 3'000'000;  // [ns] est stamps are 3 ms late: within the default 10 ms

Eigen::Vector3d offsetOf(int k) { return Eigen::Vector3d(0.1 * std::sin(k), 0.05, 0.02 * std::cos(2.0 * k)); }
double angleOf(int i) { return 0.01 * (i % 7); }  // [rad] rotation error of pose i
Eigen::Vector3d axisOf(int i) { return Eigen::Vector3d(std::cos(i), std::sin(i), 0.5).normalized(); }

Trajectory reference() {
  Trajectory ref;
  for (int k = 0; k < kPairs; ++k)
    for (int j = 0; j < 2; ++j) {
      StampedPose p = test::referencePose(k);
      p.t = static_cast<Time>(2 * k + j) * 50'000'000;
      ref.push_back(p);
    }
  return ref;
}

// est_i positions are scale * R (t_ref + o_i) + t, rotations R R_ref R_err.
Trajectory estimate(const Trajectory& ref, const Eigen::Isometry3d& T, double scale) {
  Trajectory est;
  for (int i = 0; i < static_cast<int>(ref.size()); ++i) {
    const Eigen::Vector3d o = (i % 2 == 0 ? 1.0 : -1.0) * offsetOf(i / 2);
    const Eigen::Matrix3d R = ref[i].T_world_body.linear() * geometry::expSO3(angleOf(i) * axisOf(i));
    Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
    P.linear() = T.linear() * R;
    P.translation() = scale * (T.linear() * (ref[i].T_world_body.translation() + o)) + T.translation();
    est.push_back({ref[i].t + kEstClockLag, P});
  }
  return est;
}

const Eigen::Isometry3d kT = pose(Eigen::Vector3d(0.4, -0.3, 2.2), Eigen::Vector3d(100.0, -50.0, 3.0));

double expected(int i, PoseRelation relation) {
  const double v = offsetOf(i / 2).norm();
  const double rot = 2.0 * std::sqrt(2.0) * std::sin(angleOf(i) / 2.0);
  switch (relation) {
    case PoseRelation::kTranslation: return v;
    case PoseRelation::kRotation: return rot;
    case PoseRelation::kFull: return std::sqrt(rot * rot + v * v);
    case PoseRelation::kAngleDeg: return angleOf(i) * 180.0 / std::numbers::pi;
  }
  return 0.0;
}

TEST(Ape, Se3AlignmentUndoesARigidTransformAndLeavesTheKnownPerPoseErrors) {
  const Trajectory ref = reference();
  const Trajectory est = estimate(ref, kT, 1.0);
  for (const PoseRelation rel :
       {PoseRelation::kTranslation, PoseRelation::kRotation, PoseRelation::kFull, PoseRelation::kAngleDeg}) {
    const ApeResult r = computeApe(ref, est, {rel, Alignment::kSe3, {}});
    ASSERT_EQ(r.pairs, ref.size());
    EXPECT_EQ(r.max_pairs, ref.size());
    ASSERT_EQ(r.errors.size(), ref.size());
    for (int i = 0; i < static_cast<int>(ref.size()); ++i)
      EXPECT_NEAR(r.errors[i], expected(i, rel), 1e-9) << relationName(rel) << " pose " << i;
    // The alignment found is T^-1.
    EXPECT_TRUE(r.alignment_transform.R.isApprox(kT.linear().transpose(), 1e-10));
    EXPECT_TRUE(r.alignment_transform.t.isApprox(-(kT.linear().transpose() * kT.translation()), 1e-9));
    EXPECT_EQ(r.alignment_transform.scale, 1.0);
  }
}

TEST(Ape, WithoutAlignmentTheErrorsAreTheOffsetsWhenThereIsNoRigidTransform) {
  const Trajectory ref = reference();
  const Trajectory est = estimate(ref, Eigen::Isometry3d::Identity(), 1.0);
  const ApeResult r = computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kNone, {}});
  double sum = 0.0, sum_sq = 0.0;
  for (int i = 0; i < static_cast<int>(ref.size()); ++i) {
    EXPECT_NEAR(r.errors[i], expected(i, PoseRelation::kTranslation), 1e-12);
    sum += expected(i, PoseRelation::kTranslation);
    sum_sq += std::pow(expected(i, PoseRelation::kTranslation), 2);
  }
  const double n = static_cast<double>(ref.size());
  EXPECT_NEAR(r.stats.mean, sum / n, 1e-12);
  EXPECT_NEAR(r.stats.sse, sum_sq, 1e-12);
  EXPECT_NEAR(r.stats.rmse, std::sqrt(sum_sq / n), 1e-12);
  EXPECT_EQ(r.alignment, Alignment::kNone);
  EXPECT_TRUE(r.alignment_transform.R.isIdentity());
}

TEST(Ape, WithoutAlignmentARigidOffsetIsTheError) {
  // A pure translation of the estimate by (3, 4, 0) with no other error: every translation error is 5 m.
  const Trajectory ref = test::referenceTrajectory(10);
  Trajectory est = ref;
  for (auto& p : est) p.T_world_body.pretranslate(Eigen::Vector3d(3, 4, 0));
  const ApeResult r = computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kNone, {}});
  EXPECT_NEAR(r.stats.min, 5.0, 1e-12);
  EXPECT_NEAR(r.stats.max, 5.0, 1e-12);
  EXPECT_NEAR(computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kSe3, {}}).stats.max, 0.0, 1e-9);
}

TEST(Ape, Sim3AlignmentRecoversAnExactSimilarity) {
  const Trajectory ref = test::referenceTrajectory(30);
  Trajectory est;
  for (const auto& p : ref) {
    Eigen::Isometry3d P = Eigen::Isometry3d::Identity();
    P.linear() = kT.linear() * p.T_world_body.linear();
    P.translation() = 0.4 * (kT.linear() * p.T_world_body.translation()) + kT.translation();
    est.push_back({p.t, P});
  }
  const ApeResult r = computeApe(ref, est, {PoseRelation::kFull, Alignment::kSim3, {}});
  EXPECT_NEAR(r.alignment_transform.scale, 1.0 / 0.4, 1e-10);
  EXPECT_LT(r.stats.max, 1e-9);
  // SE(3) alignment cannot undo the scale.
  EXPECT_GT(computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kSe3, {}}).stats.max, 1.0);
}

TEST(Ape, Sim3AlignmentShrinksTheScaleByTheOffsetVariance) {
  // With offsets, Umeyama's scale (Eq. 42) for aligning z = y + o onto y is c = S_yy / (S_yy + S_oo) with
  // S_yy = sum |y_i - mean_y|^2, S_oo = sum |o_i|^2 (no cross term by construction); the aligned positions are
  // c (y_i + o_i) + (1 - c) mean_y, so the error is |c o_i - (1 - c)(y_i - mean_y)|.
  const Trajectory ref = reference();
  const double s = 3.0;
  const Trajectory est = estimate(ref, kT, s);
  Eigen::Vector3d mean_y = Eigen::Vector3d::Zero();
  for (const auto& p : ref) mean_y += p.T_world_body.translation();
  mean_y /= static_cast<double>(ref.size());
  double S_yy = 0.0, S_oo = 0.0;
  for (int i = 0; i < static_cast<int>(ref.size()); ++i) {
    S_yy += (ref[i].T_world_body.translation() - mean_y).squaredNorm();
    S_oo += offsetOf(i / 2).squaredNorm();
  }
  const double c = S_yy / (S_yy + S_oo);
  const ApeResult r = computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kSim3, {}});
  EXPECT_NEAR(r.alignment_transform.scale, c / s, 1e-12);
  for (int i = 0; i < static_cast<int>(ref.size()); ++i) {
    const Eigen::Vector3d o = (i % 2 == 0 ? 1.0 : -1.0) * offsetOf(i / 2);
    const double e = (c * o - (1.0 - c) * (ref[i].T_world_body.translation() - mean_y)).norm();
    EXPECT_NEAR(r.errors[i], e, 1e-9) << i;
  }
  // Rotations are untouched by the scale: angle errors stay the constructed ones.
  const ApeResult a = computeApe(ref, est, {PoseRelation::kAngleDeg, Alignment::kSim3, {}});
  for (int i = 0; i < static_cast<int>(ref.size()); ++i)
    EXPECT_NEAR(a.errors[i], expected(i, PoseRelation::kAngleDeg), 1e-8);
}

TEST(Ape, ReportsTheEstimateStampsAndTheAlignedEstimate) {
  const Trajectory ref = reference();
  const Trajectory est = estimate(ref, kT, 1.0);
  const ApeResult r = computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kSe3, {}});
  ASSERT_EQ(r.times.size(), est.size());
  EXPECT_EQ(r.times.front(), est.front().t);
  EXPECT_EQ(r.times.back(), est.back().t);
  ASSERT_EQ(r.est_aligned.size(), est.size());
  // Aligned pose 0 is [R_ref R_err | t_ref + v_0].
  EXPECT_TRUE(r.est_aligned[0].T_world_body.translation().isApprox(ref[0].T_world_body.translation() + offsetOf(0),
                                                                   1e-9));
}

TEST(Ape, OnlyMatchedPairsCount) {
  // The estimate misses every third pose: 2/3 of the reference is matched; the stamps shift by 3 ms only.
  const Trajectory ref = reference();
  const Trajectory full = estimate(ref, Eigen::Isometry3d::Identity(), 1.0);
  Trajectory est;
  for (std::size_t i = 0; i < full.size(); ++i)
    if (i % 3 != 2) est.push_back(full[i]);
  const ApeResult r = computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kNone, {}});
  EXPECT_EQ(r.pairs, est.size());
  EXPECT_EQ(r.max_pairs, est.size());
  // A tighter max_diff than the 3 ms clock lag leaves nothing to compare.
  EXPECT_THROW(computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kNone, {2'000'000, 0}}),
               std::invalid_argument);
  // ...unless the offset compensates the lag.
  EXPECT_EQ(computeApe(ref, est, {PoseRelation::kTranslation, Alignment::kNone, {1, -kEstClockLag}}).pairs,
            est.size());
}

TEST(Ape, RejectsEmptyInputAndDegenerateAlignment) {
  const Trajectory ref = test::referenceTrajectory(5);
  EXPECT_THROW(computeApe(ref, Trajectory{}, {}), std::invalid_argument);
  EXPECT_THROW(computeApe(Trajectory{}, ref, {}), std::invalid_argument);
  // Two matched poses cannot fix a rotation.
  const Trajectory two(ref.begin(), ref.begin() + 2);
  EXPECT_THROW(computeApe(ref, two, {PoseRelation::kTranslation, Alignment::kSe3, {}}), std::invalid_argument);
  EXPECT_NO_THROW(computeApe(ref, two, {PoseRelation::kTranslation, Alignment::kNone, {}}));
}

}  // namespace
}  // namespace drover::eval
