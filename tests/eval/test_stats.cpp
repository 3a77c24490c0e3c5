// Error statistics as evo/numpy define them; expected values worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "eval/stats.hpp"

namespace drover::eval {
namespace {

TEST(ErrorStatistics, MatchesHandComputedValuesForAnOddCount) {
  // e = {3, 1, 2, 5, 4}: mean 3, squares sum 55, population variance (4+1+0+4+1)/5 = 2.
  const std::vector<double> e{3, 1, 2, 5, 4};
  const ErrorStatistics s = computeStatistics(e);
  EXPECT_EQ(s.count, 5u);
  EXPECT_DOUBLE_EQ(s.max, 5.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.mean, 3.0);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.sse, 55.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(11.0));
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(2.0));
}

TEST(ErrorStatistics, MedianOfAnEvenCountIsTheMeanOfTheTwoMiddleValues) {
  // numpy.median([4, 1, 10, 2]) = (2 + 4) / 2 = 3.
  const std::vector<double> e{4, 1, 10, 2};
  EXPECT_DOUBLE_EQ(median(e), 3.0);
  EXPECT_DOUBLE_EQ(computeStatistics(e).median, 3.0);
  const std::vector<double> two{7, 8};
  EXPECT_DOUBLE_EQ(median(two), 7.5);
}

TEST(ErrorStatistics, StdIsThePopulationStandardDeviation) {
  // numpy.std([1, 3]) = 1 (ddof = 0), not sqrt(2) (ddof = 1).
  const std::vector<double> e{1, 3};
  EXPECT_DOUBLE_EQ(computeStatistics(e).std, 1.0);
}

TEST(ErrorStatistics, SingleValue) {
  const std::vector<double> e{0.25};
  const ErrorStatistics s = computeStatistics(e);
  EXPECT_DOUBLE_EQ(s.median, 0.25);
  EXPECT_DOUBLE_EQ(s.rmse, 0.25);
  EXPECT_DOUBLE_EQ(s.std, 0.0);
  EXPECT_DOUBLE_EQ(s.sse, 0.0625);
}

TEST(ErrorStatistics, StdIsStableForASmallSpreadAroundALargeMean) {
  // 1e9 + {0, 1e-3}: the one-pass formula E[x^2] - E[x]^2 would cancel to noise; the true std is 5e-4.
  const std::vector<double> e{1e9, 1e9 + 1e-3};
  EXPECT_NEAR(computeStatistics(e).std, 5e-4, 1e-7);
}

TEST(ErrorStatistics, RejectsAnEmptyListAndNonFiniteValues) {
  EXPECT_THROW(computeStatistics(std::vector<double>{}), std::invalid_argument);
  EXPECT_THROW(median(std::vector<double>{}), std::invalid_argument);
  EXPECT_THROW(computeStatistics(std::vector<double>{1.0, std::numeric_limits<double>::quiet_NaN()}),
               std::invalid_argument);
  EXPECT_THROW(computeStatistics(std::vector<double>{std::numeric_limits<double>::infinity()}), std::invalid_argument);
}

}  // namespace
}  // namespace drover::eval
