#include "io/text_parsing.hpp"

#include <gtest/gtest.h>

#include "io/error.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

TEST(TextParsing, ParsesPlainDecimalSecondsExactlyToTheNanosecond) {
  EXPECT_EQ(parseSeconds("1403715274.302142977", "f", "line 1"), 1403715274302142977LL);
  EXPECT_EQ(parseSeconds("0.1", "f", "line 1"), 100'000'000);
  EXPECT_EQ(parseSeconds("-0.000000001", "f", "line 1"), -1);
  EXPECT_EQ(parseSeconds("12", "f", "line 1"), 12 * kNanosPerSecond);
  EXPECT_EQ(parseSeconds(".5", "f", "line 1"), 500'000'000);
  EXPECT_EQ(parseSeconds("1.0000000005", "f", "line 1"), 1'000'000'001);  // 10th decimal rounds half up
  EXPECT_EQ(parseSeconds("1.037359e-01", "f", "line 1"), 103'735'900);
}

TEST(TextParsing, FormatsSecondsWithNineDecimalsAndReadsThemBack) {
  EXPECT_EQ(formatSeconds(1403715274302142977LL), "1403715274.302142977");
  EXPECT_EQ(formatSeconds(-1), "-0.000000001");
  EXPECT_EQ(formatSeconds(0), "0.000000000");
  for (Time t : {Time{-1234567890123}, Time{0}, Time{999999999}, Time{1'700'000'000'000'000'001}})
    EXPECT_EQ(parseSeconds(formatSeconds(t), "f", ""), t);
}

TEST(TextParsing, FormatDoubleRoundTripsExactly) {
  for (double v : {0.1, -1e-300, 98765.4321 / 3.0, 6378137.0, 1.0 / 7.0})
    EXPECT_EQ(parseDouble(formatDouble(v), "f", ""), v);
}

TEST(TextParsing, RejectsJunkNonFiniteAndPartialTokensNamingFileAndLine) {
  for (const char* bad : {"", "abc", "1.5x", "nan", "inf", "-inf", "1e999", "0x10"}) {
    try {
      parseDouble(bad, "data.txt", "line 7");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("data.txt (line 7)"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parseInt64("12.5", "f", ""), IoError);
  EXPECT_THROW(parseSeconds("1.2.3", "f", ""), IoError);
  EXPECT_THROW(parseSeconds("99999999999", "f", ""), IoError);
  EXPECT_EQ(parseDouble("+2.5", "f", ""), 2.5);
}

TEST(TextParsing, SplitsFieldsAndSkipsBlankAndCommentLinesKeepingLineNumbers) {
  EXPECT_EQ(splitWhitespace("  a \tb  c\r").size(), 3u);
  const auto f = splitOn(" 1 , 2,,3 ", ',');
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[0], "1");
  EXPECT_EQ(f[2], "");
  test::TempDir dir;
  test::writeText(dir / "x.txt", "# header\r\n\r\n1 2\r\n  # indented comment\n3 4");
  const auto lines = readDataLines((dir / "x.txt").string());
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].number, 3u);
  EXPECT_EQ(lines[0].text, "1 2");
  EXPECT_EQ(lines[1].number, 5u);
  EXPECT_THROW(readDataLines((dir / "missing.txt").string()), IoError);
}

}  // namespace
}  // namespace drover::io
