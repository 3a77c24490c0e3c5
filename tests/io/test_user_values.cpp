// io/user_values: the one place that turns user-given numbers (options and config keys) into checked values.
#include "io/user_values.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "io/error.hpp"
#include "support/expect_io_error.hpp"

namespace drover::io {
namespace {

using test::expectIoError;

const ValueSource kOption = ValueSource::option("--x");
const ValueSource kKey{"platform.yaml", "line 3, key 'sim.imu_rate_hz'"};

TEST(UserValues, NumbersMustBeWholeAndFinite) {
  EXPECT_EQ(parseNumber("1e-3", kOption), 1e-3);
  EXPECT_EQ(parseNumber("+4", kOption), 4.0);
  EXPECT_EQ(parseNumber("-2.5", kOption), -2.5);
  for (const char* bad : {"", "1.5x", " 1", "abc", "0x10"})
    expectIoError([&] { parseNumber(bad, kOption); }, {"--x", "not a number"});
  for (const char* bad : {"nan", "NaN", "-nan", "inf", "-inf", "infinity", "1e400", "-1e400"})
    expectIoError([&] { parseNumber(bad, kOption); }, {"--x: expected a finite number", bad});
}

TEST(UserValues, NanFailsEveryRangeCheck) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(Range{}.contains(nan));
  EXPECT_FALSE(between(0, 1, "").contains(nan));
  EXPECT_FALSE(positive("Hz").contains(nan));
  expectIoError([&] { checkedNumber(nan, between(0, 1, ""), kOption); }, {"--x", "out of range", "[0, 1]"});
  expectIoError([&] { checkedRate(nan, 100, kOption); }, {"(0, 100] Hz"});
  expectIoError([&] { checkedSeconds(nan, Range{}, kOption); }, {"--x"});
}

TEST(UserValues, RangesHonourOpenAndClosedEnds) {
  Range r = between(0, 1, "");
  r.min_open = true;
  EXPECT_FALSE(r.contains(0.0));
  EXPECT_FALSE(r.contains(-0.0));
  EXPECT_TRUE(r.contains(1.0));
  EXPECT_FALSE(r.contains(1.0000001));
  EXPECT_EQ(r.describe(), "(0, 1]");
  EXPECT_EQ(atLeast(0, "s").describe(), "[0, inf] s");
  expectIoError([&] { parseNumber("0", r, kKey); },
                {"platform.yaml (line 3, key 'sim.imu_rate_hz'): 0 is out of range (expected (0, 1])"});
}

TEST(UserValues, SecondsBecomeNanosecondsOrFailNamingTheLimit) {
  EXPECT_EQ(checkedSeconds(0.01, atLeast(0, "s"), kOption), 10'000'000);
  EXPECT_EQ(checkedSeconds(-0.0, atLeast(0, "s"), kOption), 0);
  EXPECT_EQ(checkedSeconds(-1.5, Range{}, kOption), -1'500'000'000);
  EXPECT_EQ(checkedSeconds(1.7e9, Range{}, kOption), 1'700'000'000'000'000'000);
  EXPECT_EQ(checkedSeconds(kMaxSeconds, Range{}, kOption), 4'000'000'000'000'000'000);
  // 1e10 s used to overflow to 0 ns (so every pose "matched" with --t-offset 1e10).
  for (double s : {1e10, -1e10, 9.3e9, 1e300, -std::numeric_limits<double>::max()})
    expectIoError([&] { checkedSeconds(s, Range{}, kOption); }, {"--x", "beyond the largest time", "4000000000 s"});
  expectIoError([&] { checkedSeconds(-1, atLeast(0, "s"), kOption); }, {"-1 s is out of range (expected [0, inf] s)"});
  EXPECT_EQ(parseSecondsValue("2.5", Range{}, kOption), 2'500'000'000);
  expectIoError([&] { parseSecondsValue("inf", Range{}, kOption); }, {"finite"});
}

TEST(UserValues, RatesArePositiveFiniteAndBounded) {
  EXPECT_EQ(checkedRate(15, 60, kOption), 15);
  EXPECT_EQ(checkedRate(60, 60, kOption), 60);
  for (double hz : {0.0, -0.0, -1.0, 60.5, std::numeric_limits<double>::infinity()})
    expectIoError([&] { checkedRate(hz, 60, kOption); }, {"--x", "(0, 60] Hz"});
}

TEST(UserValues, IntegersAreParsedExactlyAndNeverWrap) {
  EXPECT_EQ(parseInteger("7", 1, 10, kOption), 7);
  EXPECT_EQ(parseInteger("+7", 1, 10, kOption), 7);
  EXPECT_EQ(parseInteger("-0", 0, 10, kOption), 0);
  EXPECT_EQ(parseInteger("9223372036854775807", 0, std::numeric_limits<std::int64_t>::max(), kOption),
            std::numeric_limits<std::int64_t>::max());
  for (const char* bad : {"0", "-1", "11"})
    expectIoError([&] { parseInteger(bad, 1, 10, kOption); }, {"--x", "out of range (expected an integer in [1, 10])"});
  // 2^63, 2^64 and 2^70 do not fit: an error naming the range, not a wrapped value.
  for (const char* huge : {"9223372036854775808", "18446744073709551616", "1180591620717411303424"})
    expectIoError([&] { parseInteger(huge, 1, 10, kOption); }, {"out of range", "[1, 10]"});
  for (const char* bad : {"1.5", "1e3", "0x10", "", "-", "12a", "nan"})
    expectIoError([&] { parseInteger(bad, 1, 10, kOption); }, {"--x: expected an integer in [1, 10]"});
}

TEST(UserValues, SeedsCoverAllOf64BitsAndNothingMore) {
  EXPECT_EQ(parseSeed("0", kOption), 0u);
  EXPECT_EQ(parseSeed("-0", kOption), 0u);
  EXPECT_EQ(parseSeed("7", kOption), 7u);
  EXPECT_EQ(parseSeed("9223372036854775808", kOption), 9223372036854775808ull);  // 2^63
  EXPECT_EQ(parseSeed("18446744073709551615", kOption), std::numeric_limits<std::uint64_t>::max());
  // -1 and 2^70 used to become 2^64 - 1 silently.
  for (const char* bad : {"-1", "18446744073709551616", "1180591620717411303424", "-9223372036854775808"})
    expectIoError([&] { parseSeed(bad, kOption); }, {"--x", "out of range", "[0, 18446744073709551615]"});
  for (const char* bad : {"1.0", "1e3", "abc", ""})
    expectIoError([&] { parseSeed(bad, kOption); }, {"--x: expected an integer seed"});
}

TEST(UserValues, EchoedValuesAreShortAndOneLine) {
  EXPECT_EQ(echo("abc"), "'abc'");
  EXPECT_EQ(echo("a\nb"), "'a?b'");
  const std::string huge(10'000'000, '7');
  const std::string e = echo(huge);
  EXPECT_LT(e.size(), 80u);
  EXPECT_NE(e.find("(10000000 characters)"), std::string::npos) << e;
  try {
    parseInteger(huge, 1, 10, kOption);
    ADD_FAILURE() << "no error";
  } catch (const IoError& err) {
    EXPECT_LT(std::string(err.what()).size(), 200u);
  }
}

}  // namespace
}  // namespace drover::io
