// Loop verification by scan matching: a synthetic scene with exact ground truth is recovered from a rough guess,
// a different scene or a guess that slides too far is rejected, and the covariance carries its floors.
#include <gtest/gtest.h>

#include <cmath>

#include "loop/loop_verifier.hpp"
#include "support/courtyard.hpp"

namespace drover::loop {
namespace {

using test::courtyard;
using test::seenFrom;

Eigen::Isometry3d pose(double x, double y, double yaw_deg) { return test::planarPose(x, y, yaw_deg); }

TEST(LoopVerifier, RecoversTheTrueRelativePoseFromAScanContextSizedGuessError) {
  const lidar::FeatureSet candidate = courtyard(0);
  const Eigen::Isometry3d T_cand_query = pose(2.0, -1.5, 150.0);
  const lidar::FeatureSet query = seenFrom(candidate, T_cand_query);
  const LoopVerifier verifier;
  const SubmapKeyframe submap[] = {{&candidate, Eigen::Isometry3d::Identity()}};
  // Scan Context's yaw is good to a sector (6 deg) and its lateral offset to the grid step (2 m).
  const LoopVerification v = verifier.verify(query, submap, 0, T_cand_query * pose(0.6, 0.5, 3.0));
  EXPECT_TRUE(v.accepted) << v.reason;
  const Eigen::Isometry3d error = T_cand_query.inverse() * v.T_candidate_query;
  // The submap is voxel-downsampled (0.2 m edges, 0.4 m planes), which bounds the accuracy to about a centimetre.
  EXPECT_LT(error.translation().norm(), 0.03);
  EXPECT_LT(Eigen::AngleAxisd(error.linear()).angle(), 2e-3);
  EXPECT_LT(v.fitness, 0.05);
  EXPECT_GT(v.inlier_ratio, 0.9);
  EXPECT_NEAR(v.correction_translation, (pose(0.6, 0.5, 3.0)).translation().norm(), 0.05);
}

TEST(LoopVerifier, TheResultIsInTheCandidatesFrameWhateverTheSubmapsWorldFrame) {
  const lidar::FeatureSet world = courtyard(0);
  const Eigen::Isometry3d T_world_cand = pose(1.0, 1.0, 20.0), T_world_other = pose(-2.0, 0.5, -10.0);
  const lidar::FeatureSet cand = seenFrom(world, T_world_cand), other = seenFrom(world, T_world_other);
  const Eigen::Isometry3d T_world_query = pose(3.0, -2.0, 100.0);
  const Eigen::Isometry3d shift = pose(50, -30, 45);  // any common frame for the submap poses
  const SubmapKeyframe submap[] = {{&other, shift * T_world_other}, {&cand, shift * T_world_cand}};
  const Eigen::Isometry3d T_cand_query = T_world_cand.inverse() * T_world_query;
  const LoopVerification v =
      LoopVerifier().verify(seenFrom(world, T_world_query), submap, 1, T_cand_query * pose(0.3, 0.3, 2.0));
  EXPECT_TRUE(v.accepted) << v.reason;
  EXPECT_LT((T_cand_query.inverse() * v.T_candidate_query).translation().norm(), 0.03);
}

TEST(LoopVerifier, RejectsAnotherPlace) {
  const lidar::FeatureSet candidate = courtyard(0), elsewhere = courtyard(2);
  const SubmapKeyframe submap[] = {{&candidate, Eigen::Isometry3d::Identity()}};
  const LoopVerification v = LoopVerifier().verify(elsewhere, submap, 0, Eigen::Isometry3d::Identity());
  EXPECT_FALSE(v.accepted);
  EXPECT_NE(v.reason.find("rejected"), std::string::npos);
}

TEST(LoopVerifier, RejectsASolutionThatSlidFarFromTheGuess) {
  const lidar::FeatureSet candidate = courtyard(0);
  const Eigen::Isometry3d T_cand_query = pose(2.0, -1.5, 30.0);
  LoopVerifierConfig c;
  c.max_correction_translation = 0.3;  // the guess below is 0.78 m off
  const SubmapKeyframe submap[] = {{&candidate, Eigen::Isometry3d::Identity()}};
  const LoopVerification v =
      LoopVerifier(c).verify(seenFrom(candidate, T_cand_query), submap, 0, T_cand_query * pose(0.6, 0.5, 0.0));
  EXPECT_TRUE(v.converged);
  EXPECT_FALSE(v.accepted);
  EXPECT_NE(v.reason.find("from the guess"), std::string::npos) << v.reason;
}

TEST(LoopVerifier, CovarianceIncludesTheFloorsAndIsTheInverseOfTheInformation) {
  const lidar::FeatureSet candidate = courtyard(0);
  LoopVerifierConfig c;
  c.sigma_floor_position = 0.2;
  c.sigma_floor_rotation = 0.01;
  const SubmapKeyframe submap[] = {{&candidate, Eigen::Isometry3d::Identity()}};
  const LoopVerification v = LoopVerifier(c).verify(seenFrom(candidate, pose(1, 1, 10)), submap, 0, pose(1.2, 1, 12));
  ASSERT_TRUE(v.accepted) << v.reason;
  for (int i = 0; i < 3; ++i) EXPECT_GE(v.covariance(i, i), 0.2 * 0.2);
  for (int i = 3; i < 6; ++i) EXPECT_GE(v.covariance(i, i), 0.01 * 0.01);
  EXPECT_LT((v.covariance * v.information() - geometry::Matrix6d::Identity()).norm(), 1e-6);
  EXPECT_LT((v.information() - v.information().transpose()).norm(), 1e-9 * v.information().norm());
}

// A fit worse than sigma_fitness_reference widens the whole covariance by (fitness / reference)^2; a better one, or
// a reference of 0, leaves it alone.
TEST(LoopVerifier, AFitWorseThanTheFitnessReferenceWidensTheCovarianceByTheSquaredRatio) {
  const lidar::FeatureSet candidate = courtyard(0);
  const SubmapKeyframe submap[] = {{&candidate, Eigen::Isometry3d::Identity()}};
  const lidar::FeatureSet query = seenFrom(candidate, pose(1, 1, 10));
  const LoopVerification plain = LoopVerifier().verify(query, submap, 0, pose(1.2, 1, 12));
  ASSERT_TRUE(plain.accepted) << plain.reason;
  ASSERT_GT(plain.fitness, 1e-4);
  LoopVerifierConfig c;
  c.sigma_fitness_reference = plain.fitness / 3;  // this fit is 3x worse than the reference
  const LoopVerification wide = LoopVerifier(c).verify(query, submap, 0, pose(1.2, 1, 12));
  EXPECT_LT((wide.covariance - 9.0 * plain.covariance).norm(), 1e-9 * plain.covariance.norm());
  EXPECT_LT((wide.covariance * wide.information() - geometry::Matrix6d::Identity()).norm(), 1e-6);
  EXPECT_EQ(wide.T_candidate_query.matrix(), plain.T_candidate_query.matrix()) << "only the covariance changes";
  c.sigma_fitness_reference = plain.fitness * 2;  // a better fit than the reference
  EXPECT_EQ(LoopVerifier(c).verify(query, submap, 0, pose(1.2, 1, 12)).covariance, plain.covariance);
  c.sigma_fitness_reference = -0.1;
  EXPECT_NE(c.validate().find("sigma_fitness_reference"), std::string::npos);
}

TEST(LoopVerifier, RejectsBadArguments) {
  const lidar::FeatureSet f = courtyard(0);
  const LoopVerifier verifier;
  EXPECT_THROW(verifier.verify(f, {}, 0, Eigen::Isometry3d::Identity()), std::invalid_argument);
  const SubmapKeyframe one[] = {{&f, Eigen::Isometry3d::Identity()}};
  EXPECT_THROW(verifier.verify(f, one, 1, Eigen::Isometry3d::Identity()), std::invalid_argument);
  const SubmapKeyframe null_features[] = {{nullptr, Eigen::Isometry3d::Identity()}};
  EXPECT_THROW(verifier.verify(f, null_features, 0, Eigen::Isometry3d::Identity()), std::invalid_argument);
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan(0, 3) = NAN;
  EXPECT_THROW(verifier.verify(f, one, 0, nan), std::invalid_argument);
  LoopVerifierConfig bad;
  bad.max_fitness = 0;
  EXPECT_THROW(LoopVerifier{bad}, std::invalid_argument);
  bad = {};
  bad.min_inlier_ratio = 1.5;
  EXPECT_THROW(LoopVerifier{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace drover::loop
