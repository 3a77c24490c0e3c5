// Every IoError is one line of bounded length, whatever the input put into it: a 200,000-digit token or a megabyte
// file name cannot make a 65 kB error line, and line breaks cannot split it.
#include <gtest/gtest.h>

#include <string>

#include "io/error.hpp"

namespace drover::io {
namespace {

TEST(ErrorMessage, BoundedTextKeepsShortTextAndShowsControlCharactersAsQuestionMarks) {
  EXPECT_EQ(boundedText("abc", 10), "abc");
  EXPECT_EQ(boundedText("a\nb\tc", 10), "a?b?c");
}

TEST(ErrorMessage, BoundedTextCutsLongTextAndSaysHowLongItWas) {
  EXPECT_EQ(boundedText(std::string(12, 'x'), 5), "xxxxx... (12 characters)");
}

TEST(ErrorMessage, AnIoErrorFromHugePartsStaysOneLineUnderTwoThousandCharactersAndNamesTheFileFirst) {
  const std::string huge(200000, '7');
  const IoError e("/data/seq/times.txt", "line 2" + huge, "unparsable timestamp: '" + huge + "\n'");
  const std::string what = e.what();
  EXPECT_LT(what.size(), 2000u);
  EXPECT_EQ(what.find('\n'), std::string::npos);
  EXPECT_EQ(what.rfind("/data/seq/times.txt (line 2777", 0), 0u) << what.substr(0, 80);
  EXPECT_NE(what.find("(200025 characters)"), std::string::npos);
  EXPECT_EQ(e.file(), "/data/seq/times.txt");
}

TEST(ErrorMessage, AMessageUnderTheBoundsIsUnchanged) {
  const IoError e("calib.txt", "line 5", "key 'Tr' has a value that is not a number: '-x'");
  EXPECT_STREQ(e.what(), "calib.txt (line 5): key 'Tr' has a value that is not a number: '-x'");
}

}  // namespace
}  // namespace drover::io
