// Every number typed on the command line goes through one place (io/user_values.hpp): NaN, inf, junk, values out of
// range or beyond 64 bits are exit code 2 with one `[error] --option: ...` line naming the valid range, before any
// work. Also: CLI11's own messages are one short line, and `-q` is accepted after every command.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {

// The lines of `output` (no trailing empty line).
std::vector<std::string> lines(const std::string& output) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  while (begin < output.size()) {
    std::size_t end = output.find('\n', begin);
    if (end == std::string::npos) end = output.size();
    out.push_back(output.substr(begin, end - begin));
    begin = end + 1;
  }
  return out;
}

// Exit code 2 and exactly one line, "[error] ..." holding every fragment.
void expectOneErrorLine(const std::string& args, const std::vector<std::string>& fragments) {
  const CliResult r = runDrover(args);
  EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
  const std::vector<std::string> l = lines(r.output);
  ASSERT_EQ(l.size(), 1u) << args << "\n" << r.output;
  EXPECT_EQ(l[0].rfind("[error] ", 0), 0u) << l[0];
  for (const std::string& f : fragments) EXPECT_TRUE(contains(l[0], f)) << args << "\n" << l[0];
}

struct NumericOption {
  std::string command;  // with dummy positional arguments: the option is checked before they are read
  std::string option;
  std::vector<std::string> bad;
};

const char* const kTwo64 = "18446744073709551616";
const char* const kTwo70 = "1180591620717411303424";

std::vector<NumericOption> everyNumericOption() {
  // A few per kind here (each run starts the binary); tests/io/test_user_values.cpp has the full lists.
  const std::vector<std::string> seconds = {"nan", "-inf", "1e400", "1e10"};
  const std::vector<std::string> count = {"0", "-1", "1.5", kTwo70};
  const std::string ape = "eval ape ref.txt est.txt", track = "features track ds --format sim --out o";
  const std::string loop_eval = "loop eval ds", run = "run ds --format kitti --out o", sim = "sim --scenario x --out o";
  const std::string graph = "graph optimize in.g2o out.g2o", detect = "features detect img.png";
  return {
      {ape, "--t-max-diff", {"nan", "inf", "-1", "1e10", "abc"}},
      {ape, "--t-offset", {"nan", "inf", "1e10", "-1e10"}},
      {"eval rpe ref.txt est.txt", "--delta", {"nan", "0", "-1", "inf"}},
      {detect, "--max", count},
      {detect, "--darken", {"nan", "0", "-0.5", "1.5", "inf"}},
      {detect, "--seed", {"-1", kTwo64, kTwo70, "1.5", "nan"}},
      {detect, "--input-size", {"0x480", "640x-8", "640x" + std::string(kTwo70), "nanxnan"}},
      {track, "--overlay-every", {"-1", "nan", kTwo70}},
      {track, "--max-frames", count},
      {track, "--start", seconds},
      {track, "--duration", seconds},
      {graph, "--max-iterations", count},
      {graph, "--loss-scale", {"nan", "0", "-3", "inf"}},
      {graph, "--threads", count},
      {"info ds --format kitti", "--max-frames", count},
      {loop_eval, "--keyframe-distance", {"nan", "0", "-1", "inf"}},
      {loop_eval, "--true-distance", {"nan", "0", "-1", "inf"}},
      {loop_eval, "--threshold", {"nan", "-0.1", "2.5", "inf"}},
      {loop_eval, "--max-frames", count},
      {run, "--start", seconds},
      {run, "--duration", seconds},
      {run, "--max-frames", count},
      {run, "--rate", {"nan", "0", "-1", "inf", "1e3"}},
      {sim, "--seed", {"-1", kTwo64, kTwo70, "1.5", "nan"}},
      {sim, "--duration", {"nan", "-1", "1e9", "1e12", "inf"}},
      {sim, "--camera-rate", {"0", "-15", "nan", "inf", "1e9"}},
  };
}

TEST(OptionValuesCli, EveryNumericOptionRefusesNanInfJunkAndOutOfRangeValuesInOneLineNamingIt) {
  for (const NumericOption& o : everyNumericOption())
    for (const std::string& v : o.bad) expectOneErrorLine(o.command + " " + o.option + " " + v, {o.option + ":"});
}

TEST(OptionValuesCli, OutOfRangeMessagesNameTheValidRange) {
  expectOneErrorLine("run ds --format kitti --out o --max-frames 0",
                     {"--max-frames: '0' is out of range (expected an integer in [1, 1000000000])"});
  expectOneErrorLine("features detect img.png --darken nan", {"--darken", "finite"});
  expectOneErrorLine("features detect img.png --darken 2", {"--darken: 2 is out of range (expected (0, 1])"});
  expectOneErrorLine("loop eval ds --threshold 3", {"--threshold: 3 is out of range (expected [0, 2])"});
  expectOneErrorLine("sim --scenario straight --out o --seed -1",
                     {"--seed: '-1' is out of range (expected an integer seed in [0, 18446744073709551615])"});
  expectOneErrorLine("sim --scenario straight --out o --camera-rate 0",
                     {"--camera-rate: 0 Hz is out of range (expected (0, 60] Hz)"});
  expectOneErrorLine("eval ape r e --t-offset 1e10",
                     {"--t-offset: 10000000000 s is beyond the largest time accepted, +-4000000000 s"});
}

TEST(OptionValuesCli, Cli11sOwnMessagesAreOneShortErrorLine) {
  expectOneErrorLine("eval ape r e --format bogus", {"--format", "bogus"});
  expectOneErrorLine("info ds", {"--format"});  // a required option missing
  expectOneErrorLine("info ds --format kitti --no-such-option", {"--no-such-option"});
  expectOneErrorLine("", {"subcommand"});
  // A 100 kB value (the kernel allows 128 kB per argument) is not echoed whole.
  const CliResult r = runDrover("eval ape r e --format " + std::string(100'000, 'x'));
  EXPECT_EQ(r.exit_code, 2) << r.output.substr(0, 300);
  EXPECT_LT(r.output.size(), 400u) << r.output.substr(0, 400);
  EXPECT_EQ(lines(r.output).size(), 1u) << r.output.substr(0, 400);
}

TEST(OptionValuesCli, QuietIsAcceptedAfterEveryCommand) {
  // Each fails on its missing input, which shows that -q itself was parsed (an unknown -q would fail first).
  TempDir dir;
  const std::string missing = (dir / "missing").string();
  const std::vector<std::string> commands = {
      "info " + missing + " --format kitti",
      "eval ape " + missing + " " + missing,
      "eval rpe " + missing + " " + missing,
      "eval kitti " + missing + " " + missing,
      "run " + missing + " --format kitti --out " + (dir / "o").string(),
      "loop pair " + missing + " " + missing,
      "loop eval " + missing,
      "graph optimize " + missing + " " + (dir / "o.g2o").string(),
      "features detect " + missing + ".png",
      "features track " + missing + " --format sim --out " + (dir / "t").string(),
      "sim --scenario nosuch --out " + (dir / "s").string(),
  };
  for (const std::string& c : commands) {
    const CliResult r = runDrover(c + " -q");
    EXPECT_EQ(r.exit_code, 2) << c << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "not expected")) << c << "\n" << r.output;
    EXPECT_FALSE(contains(r.output, "-q")) << c << "\n" << r.output;
    EXPECT_EQ(lines(r.output).size(), 1u) << c << "\n" << r.output;
  }
}

TEST(OptionValuesCli, AConfigThatIsAFolderIsAnError) {
  TempDir dir;
  expectOneErrorLine("sim --scenario straight --duration 1 --no-camera --config " + dir.path().string() + " --out " +
                         (dir / "s").string(),
                     {dir.path().string(), "is a folder"});
  EXPECT_FALSE(std::filesystem::exists(dir / "s"));
}

TEST(OptionValuesCli, ATenMegabyteConfigValueIsEchoedShortened) {
  TempDir dir;
  writeText(dir / "big.yaml", "sim:\n  lidar_model: " + std::string(10'000'000, 'v') + "\n");
  const CliResult r = runDrover("sim --scenario straight --config " + (dir / "big.yaml").string() + " --out " +
                                (dir / "s").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_LT(r.output.size(), 400u) << r.output.substr(0, 400);
  EXPECT_TRUE(contains(r.output, "key 'sim.lidar_model'")) << r.output.substr(0, 400);
  EXPECT_TRUE(contains(r.output, "(10000000 characters)")) << r.output.substr(0, 400);
}

}  // namespace
}  // namespace drover::test
