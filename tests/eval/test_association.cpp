// Time association with evo's associate_trajectories semantics (nearest stamp, shorter trajectory iterated,
// |dt| <= max_diff, offset on the second trajectory's stamps).
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include "eval/association.hpp"
#include "support/units.hpp"

namespace drover::eval {
namespace {

using ::drover::test::kMs;

Trajectory stamps(const std::vector<Time>& ts) {
  Trajectory t;
  for (const Time s : ts) t.push_back({s, Eigen::Isometry3d::Identity()});
  return t;
}

using Idx = std::vector<std::size_t>;

TEST(Association, PairsEqualStamps) {
  const Association a = associate(stamps({0, 100 * kMs, 200 * kMs}), stamps({0, 100 * kMs, 200 * kMs}));
  EXPECT_EQ(a.first, (Idx{0, 1, 2}));
  EXPECT_EQ(a.second, (Idx{0, 1, 2}));
  EXPECT_EQ(a.max_pairs, 3u);
}

TEST(Association, MaxDiffBoundaryIsInclusive) {
  // Second stamps 10 ms and 10 ms + 1 ns after the first ones; max_diff = 10 ms keeps exactly the first.
  const Association a = associate(stamps({0, 1000 * kMs}), stamps({10 * kMs, 1010 * kMs + 1}), {10 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{0}));
  EXPECT_EQ(a.second, (Idx{0}));
}

TEST(Association, AnOffsetThatLeavesInt64NanosecondsNeverMatchesPosesCenturiesApart) {
  // 9e9 s (the readers' largest stamp) + a 4e9 s offset (the CLI's largest) is beyond int64 ns; wrapped, the
  // difference to a stamp of -5.4e9 s would come out as 0 and pair them.
  const Time t = -5'446'744'073'709'551'616;  // 9e18 + 4e18 - 2^64 [ns]
  const Association a = associate(stamps({t}), stamps({9'000'000'000'000'000'000 - 1, 9'000'000'000'000'000'000}),
                                  {10 * kMs, 4'000'000'000'000'000'000});
  EXPECT_TRUE(a.first.empty());
  EXPECT_EQ(a.max_pairs, 1u);
}

TEST(Association, IteratesTheShorterTrajectoryAndMayReuseAPoseOfTheLonger) {
  // first (longer): 0, 10, 20, 30 ms; second (shorter): 9, 11 ms. Both second stamps are nearest to 10 ms.
  const Association a = associate(stamps({0, 10 * kMs, 20 * kMs, 30 * kMs}), stamps({9 * kMs, 11 * kMs}),
                                  {5 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{1, 1}));
  EXPECT_EQ(a.second, (Idx{0, 1}));
  EXPECT_EQ(a.max_pairs, 2u);
}

TEST(Association, WhenTheSecondIsLongerItsPosesAreSearched) {
  // first (shorter): 10, 31 ms; second (longer): 0, 9, 12, 30, 40 ms -> 10 ms pairs with 9 ms (1 ms away), 31 ms
  // with 30 ms.
  const Association a = associate(stamps({10 * kMs, 31 * kMs}), stamps({0, 9 * kMs, 12 * kMs, 30 * kMs, 40 * kMs}),
                                  {5 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{0, 1}));
  EXPECT_EQ(a.second, (Idx{1, 3}));
}

TEST(Association, TiesGoToTheEarlierStampLikeNumpyArgmin) {
  // 15 ms is 5 ms from both 10 and 20 ms: the earlier index wins.
  const Association a = associate(stamps({15 * kMs}), stamps({10 * kMs, 20 * kMs}), {5 * kMs, 0});
  EXPECT_EQ(a.second, (Idx{0}));
}

TEST(Association, EqualLengthsIterateTheSecondTrajectory) {
  // Equal lengths: evo's snd_longer is false, so the second trajectory is iterated and the first searched.
  // first: 0, 4 ms; second: 2, 100 ms. Iterating the second: 2 ms ties between 0 and 4 ms -> index 0.
  // Iterating the first instead would pair 0 and 4 ms both with 2 ms.
  const Association a = associate(stamps({0, 4 * kMs}), stamps({2 * kMs, 100 * kMs}), {5 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{0}));
  EXPECT_EQ(a.second, (Idx{0}));
}

TEST(Association, OffsetShiftsTheSecondTrajectoryWhicheverIsLonger) {
  // The second trajectory runs 1 s late in its own clock: offset -1 s brings it back.
  const Trajectory first = stamps({0, 100 * kMs, 200 * kMs, 300 * kMs});
  const Trajectory second_short = stamps({1100 * kMs, 1300 * kMs});
  const Association a = associate(first, second_short, {kMs, -1000 * kMs});
  EXPECT_EQ(a.first, (Idx{1, 3}));
  EXPECT_EQ(a.second, (Idx{0, 1}));
  EXPECT_EQ(associate(first, second_short, {kMs, 0}).size(), 0u);

  const Trajectory first_short = stamps({100 * kMs, 300 * kMs});
  const Trajectory second_long = stamps({1000 * kMs, 1100 * kMs, 1200 * kMs, 1300 * kMs});
  const Association b = associate(first_short, second_long, {kMs, -1000 * kMs});
  EXPECT_EQ(b.first, (Idx{0, 1}));
  EXPECT_EQ(b.second, (Idx{1, 3}));
}

TEST(Association, GapsLeavePosesUnmatched) {
  // The second trajectory has a gap between 100 and 400 ms; 200 and 300 ms find nothing within 10 ms.
  const Association a = associate(stamps({0, 100 * kMs, 200 * kMs, 300 * kMs, 400 * kMs}),
                                  stamps({1 * kMs, 99 * kMs, 401 * kMs}), {10 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{0, 1, 4}));
  EXPECT_EQ(a.second, (Idx{0, 1, 2}));
  EXPECT_EQ(a.max_pairs, 3u);
}

TEST(Association, StampsBeyondEitherEndMatchTheEndPoses) {
  // The iterated (shorter) second trajectory starts before and ends after the first one.
  const Association a = associate(stamps({0, 50 * kMs, 100 * kMs}), stamps({-3 * kMs, 103 * kMs}), {5 * kMs, 0});
  EXPECT_EQ(a.first, (Idx{0, 2}));
  EXPECT_EQ(a.second, (Idx{0, 1}));
}

TEST(Association, RejectsUnorderedStampsAndANegativeMaxDiff) {
  EXPECT_THROW(associate(stamps({0, 2, 1}), stamps({0, 1})), std::invalid_argument);
  EXPECT_THROW(associate(stamps({0, 1}), stamps({0, 0})), std::invalid_argument);
  EXPECT_THROW(associate(stamps({0}), stamps({0}), {-1, 0}), std::invalid_argument);
}

TEST(Association, EmptyTrajectoryGivesNoPairs) {
  EXPECT_EQ(associate(stamps({}), stamps({0, 1})).size(), 0u);
}

}  // namespace
}  // namespace drover::eval
