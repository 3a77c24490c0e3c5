// The fuzz harness itself: a crash, a hang, a foreign exception and silently wrong data in one case are each
// reported against that case, and the cases after it still run (otherwise a fuzz test could not fail).
#include <gtest/gtest.h>

#include <csignal>
#include <stdexcept>
#include <thread>

#include "fuzz/cli_fuzz.hpp"
#include "fuzz/reader_fuzz.hpp"
#include "io/kitti_fixture_util.hpp"

namespace drover::test::fuzz {
namespace {

TEST(FuzzHarness, ReportsEachCrashHangForeignExceptionAndWrongResultAgainstItsCase) {
  TempDir dir;
  const std::string path = (dir / "input.txt").string();
  writeText(path, "ok");
  std::vector<FuzzCase> cases;
  for (const char* what : {"ok", "io", "segv", "ok", "hang", "runtime", "wrong", "ok"})
    cases.push_back({path, what, "ok"});
  const auto body = [&]() -> std::string {
    const std::string what = readText(path);
    if (what == "io") io::fail(path, "line 1", "bad");
    if (what == "segv") std::raise(SIGSEGV);
    if (what == "hang") std::this_thread::sleep_for(std::chrono::seconds(30));
    if (what == "runtime") throw std::runtime_error("not an IoError");
    return what == "wrong" ? "NaN returned" : "";
  };
  const std::vector<CaseResult> r = runCases(cases, body, 64, 1.0);
  ASSERT_EQ(r.size(), cases.size());
  const std::vector<Outcome> expected = {Outcome::kOk,   Outcome::kIoError,        Outcome::kSignal, Outcome::kOk,
                                         Outcome::kHang, Outcome::kOtherException, Outcome::kWrong,  Outcome::kOk};
  for (std::size_t i = 0; i < r.size(); ++i)
    EXPECT_EQ(r[i].outcome, expected[i]) << "case " << i << ": " << r[i].message;
  EXPECT_EQ(readText(path), "ok") << "the file of a case that crashed is put back";
}

TEST(FuzzHarness, CliContractCatchesWrongCodesExtraErrorLinesAndUnnamedInputs) {
  const std::map<std::string, std::string> vars = {{"{out}", "/nonexistent"}};
  const CliCase c{"x", Expect::kEither, "--seed", {}};
  EXPECT_EQ(contractBreach(c, {0, "[info] fine\n"}, vars), "");
  EXPECT_EQ(contractBreach(c, {2, "[error] --seed must be >= 0\n"}, vars), "");
  EXPECT_NE(contractBreach(c, {1, "[error] --seed\n"}, vars), "");
  EXPECT_NE(contractBreach(c, {2, "[error] --seed bad\n[error] again\n"}, vars), "");
  EXPECT_NE(contractBreach(c, {2, "Could not convert: --seed = -1\nRun with --help\n"}, vars), "");
  EXPECT_NE(contractBreach(c, {2, "[error] something is wrong\n"}, vars), "");
  EXPECT_NE(contractBreach(c, {124, ""}, vars), "");
  const CliCase must_fail{"x", Expect::kError, "", {}};
  EXPECT_NE(contractBreach(must_fail, {0, ""}, vars), "");
  const CliCase with_output{"x", Expect::kEither, "", {"{out}/report.json"}};
  EXPECT_NE(contractBreach(with_output, {0, ""}, vars), "") << "exit 0 without its output";
}

}  // namespace
}  // namespace drover::test::fuzz
