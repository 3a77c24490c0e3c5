// Place-recognition counting (loop/place_recognition_eval.hpp) against hand-computed answers.
#include "loop/place_recognition_eval.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace drover::loop {
namespace {

// has_candidate, distance, candidate_correct, has_true_revisit
std::vector<PlaceQuery> sample() {
  return {
      {true, 0.10, true, true},    // TP at 0.15; FN at 0.05
      {true, 0.12, false, true},   // FP and FN at 0.15 (matched the wrong place at a revisit)
      {true, 0.30, true, true},    // FN at 0.15, TP at 0.35
      {true, 0.08, false, false},  // FP at 0.15
      {true, 0.40, false, false},  // TN at 0.15
      {false, 1.00, false, true},  // FN always (no candidate)
      {false, 1.00, false, false}, // TN always
  };
}

TEST(CountAt, CountsTpFpFnTnAsDefinedInTheHeader) {
  const PrCounts c = countAt(sample(), 0.15);
  EXPECT_EQ(c.queries, 7u);
  EXPECT_EQ(c.true_revisits, 4u);
  EXPECT_EQ(c.tp, 1u);
  EXPECT_EQ(c.fp, 2u);
  EXPECT_EQ(c.fn, 3u);
  EXPECT_EQ(c.tn, 2u);
  EXPECT_DOUBLE_EQ(c.precision, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(c.recall, 1.0 / 4.0);
  EXPECT_DOUBLE_EQ(c.f1, 2.0 * (1.0 / 3.0) * 0.25 / (1.0 / 3.0 + 0.25));  // 2/7
  EXPECT_NEAR(c.f1, 2.0 / 7.0, 1e-12);
}

TEST(CountAt, DistanceEqualToTheThresholdIsNotADetection) {
  const PrCounts c = countAt({{true, 0.2, true, true}}, 0.2);
  EXPECT_EQ(c.tp, 0u);
  EXPECT_EQ(c.fn, 1u);
  EXPECT_DOUBLE_EQ(c.precision, 1.0);  // nothing detected
  EXPECT_DOUBLE_EQ(c.recall, 0.0);
  EXPECT_DOUBLE_EQ(c.f1, 0.0);
}

TEST(CountAt, NoQueriesGivesPrecisionAndRecallOne) {
  const PrCounts c = countAt({}, 0.1);
  EXPECT_DOUBLE_EQ(c.precision, 1.0);
  EXPECT_DOUBLE_EQ(c.recall, 1.0);
  EXPECT_DOUBLE_EQ(c.f1, 1.0);
}

TEST(CountAt, RejectsANonFiniteThreshold) {
  EXPECT_THROW(countAt(sample(), std::nan("")), std::invalid_argument);
}

TEST(PrecisionRecallCurve, RecallGrowsAndPrecisionFollowsTheHandCounts) {
  const std::vector<PrCounts> curve = precisionRecallCurve(sample(), {0.05, 0.09, 0.15, 0.35, 0.5});
  ASSERT_EQ(curve.size(), 5u);
  // 0.05: nothing detected. 0.09: only the 0.08 FP. 0.15: 1 TP 2 FP. 0.35: 2 TP 2 FP. 0.5: 2 TP 3 FP.
  EXPECT_DOUBLE_EQ(curve[0].precision, 1.0);
  EXPECT_DOUBLE_EQ(curve[0].recall, 0.0);
  EXPECT_DOUBLE_EQ(curve[1].precision, 0.0);
  EXPECT_DOUBLE_EQ(curve[1].recall, 0.0);
  EXPECT_DOUBLE_EQ(curve[2].precision, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(curve[3].precision, 0.5);
  EXPECT_DOUBLE_EQ(curve[3].recall, 0.5);
  EXPECT_DOUBLE_EQ(curve[4].precision, 0.4);
  EXPECT_DOUBLE_EQ(curve[4].recall, 0.5);
  EXPECT_DOUBLE_EQ(curve[4].threshold, 0.5);
}

TEST(ThresholdRange, IncludesBothEndsWithoutAccumulatedRounding) {
  const std::vector<double> t = thresholdRange(0.05, 0.5, 0.05);
  ASSERT_EQ(t.size(), 10u);
  EXPECT_DOUBLE_EQ(t.front(), 0.05);
  EXPECT_NEAR(t.back(), 0.5, 1e-12);
  EXPECT_THROW(thresholdRange(0.5, 0.05, 0.05), std::invalid_argument);
  EXPECT_THROW(thresholdRange(0.05, 0.5, 0.0), std::invalid_argument);
}

TruthConfig truthConfig() {
  TruthConfig c;
  c.true_distance = 3.0;
  c.correct_distance = 6.0;
  c.exclude_recent = 2;
  c.min_age = 10.0;
  return c;
}

TEST(EligibleEnd, ExcludesTheRecentEntriesAndThoseYoungerThanMinAge) {
  // Keyframes at 0, 5, 10, ..., 45 s.
  std::vector<Time> times;
  for (int i = 0; i < 10; ++i) times.push_back(fromSeconds(5.0 * i));
  // Query 9 (45 s): exclude_recent leaves 0..6; min_age (<= 35 s) leaves 0..7: so 0..6.
  EXPECT_EQ(eligibleEnd(times, 9, truthConfig()), 7u);
  // Query 3 (15 s): exclude_recent leaves 0; min_age (<= 5 s) leaves 0..1: so 0.
  EXPECT_EQ(eligibleEnd(times, 3, truthConfig()), 1u);
  TruthConfig slow = truthConfig();
  slow.exclude_recent = 0;
  slow.min_age = 22.0;  // query 9: <= 23 s: keyframes 0..4
  EXPECT_EQ(eligibleEnd(times, 9, slow), 5u);
  EXPECT_EQ(eligibleEnd(times, 0, truthConfig()), 0u);
  EXPECT_THROW(eligibleEnd(times, 10, truthConfig()), std::invalid_argument);
}

TEST(MatchAgainstTruth, FindsTheNearestEligibleKeyframeAndJudgesTheCandidate) {
  // A loop: keyframes along x, the last one back near the start (1 m from keyframe 1).
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0},  {10, 0, 0}, {20, 0, 0}, {30, 0, 0},
                                          {20, 5, 0}, {10, 5, 0}, {10, 1, 0}};
  std::vector<Time> times;
  for (int i = 0; i < 7; ++i) times.push_back(fromSeconds(10.0 * i));
  TruthMatch m = matchAgainstTruth(p, times, 6, 0, truthConfig());
  EXPECT_TRUE(m.has_true_revisit);
  EXPECT_EQ(m.nearest, 1);
  EXPECT_DOUBLE_EQ(m.nearest_distance, 1.0);
  EXPECT_NEAR(m.candidate_distance, std::hypot(10.0, 1.0), 1e-12);
  EXPECT_FALSE(m.candidate_correct);  // 10.05 m > 6 m
  m = matchAgainstTruth(p, times, 6, 1, truthConfig());
  EXPECT_TRUE(m.candidate_correct);
  // Keyframe 5 is 4 m away but too recent (exclude_recent = 2): it never counts, and 4 m > 3 m anyway. Query 4
  // (20, 5): eligible 0..1, nearest keyframe 1 at hypot(10, 5) m: no true revisit.
  m = matchAgainstTruth(p, times, 4, -1, truthConfig());
  EXPECT_FALSE(m.has_true_revisit);
  EXPECT_EQ(m.nearest, 1);
  EXPECT_DOUBLE_EQ(m.candidate_distance, -1.0);
  EXPECT_FALSE(m.candidate_correct);
}

TEST(MatchAgainstTruth, NoEligibleKeyframeMeansNoRevisit) {
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {0, 0, 0}};
  const std::vector<Time> times = {0, fromSeconds(1.0)};
  const TruthMatch m = matchAgainstTruth(p, times, 1, -1, truthConfig());
  EXPECT_FALSE(m.has_true_revisit);
  EXPECT_EQ(m.nearest, -1);
}

TEST(MatchAgainstTruth, RejectsMismatchedSizesAndBadIndices) {
  const std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(matchAgainstTruth(p, {0}, 0, -1, truthConfig()), std::invalid_argument);
  EXPECT_THROW(matchAgainstTruth(p, {0, 1}, 0, 5, truthConfig()), std::invalid_argument);
  TruthConfig bad = truthConfig();
  bad.true_distance = 0;
  EXPECT_THROW(matchAgainstTruth(p, {0, 1}, 1, -1, bad), std::invalid_argument);
}

}  // namespace
}  // namespace drover::loop
