// `drover eval` end to end on TUM/KITTI files the tests write. Expected figures are closed forms of the
// constructed trajectories (see each test).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;


std::size_t countLinesWith(const std::string& s, const std::string& part) {
  std::istringstream in(s);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) n += contains(line, part) ? 1 : 0;
  return n;
}

// One TUM line with identity orientation; t in seconds.
std::string tumLine(double t, double x, double y, double z) {
  std::ostringstream s;
  s.precision(17);
  s << t << " " << x << " " << y << " " << z << " 0 0 0 1\n";
  return s.str();
}

// Reference: 10 poses at x = i m, 0.1 s apart. Estimate: x = 1.1 i m, stamps 5 ms late (inside the 10 ms
// default), so the APE translation errors are 0.1 i m: 0, 0.1, ..., 0.9.
struct LineFixture {
  TempDir dir;
  fs::path ref = dir / "ref.txt";
  fs::path est = dir / "est.txt";
  fs::path json = dir / "out.json";
  LineFixture(double est_clock_lag_s = 0.005) {
    std::string r, e;
    for (int i = 0; i < 10; ++i) {
      r += tumLine(100.0 + 0.1 * i, i, 0, 0);
      e += tumLine(100.0 + 0.1 * i + est_clock_lag_s, 1.1 * i, 0, 0);
    }
    writeText(ref, r);
    writeText(est, e);
  }
  std::string files() const { return ref.string() + " " + est.string() + " --json " + json.string(); }
};

TEST(EvalCli, ApeWritesEvoStatisticsUnderTheAgreedKeys) {
  LineFixture f;
  const CliResult r = runDrover("eval ape " + f.files());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "APE w.r.t. translation part (m)")) << r.output;
  EXPECT_TRUE(contains(r.output, "matched pose pairs: 10 of max. 10")) << r.output;
  EXPECT_TRUE(contains(r.output, "      rmse\t")) << r.output;
  const Json j = readJson(f.json);
  // Errors 0.1 i, i = 0..9: mean 0.45, median (0.4 + 0.5) / 2, sse 0.01 * 285, population var 0.01 * 8.25.
  EXPECT_NEAR(j["max"].get<double>(), 0.9, 1e-12);
  EXPECT_NEAR(j["min"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(j["mean"].get<double>(), 0.45, 1e-12);
  EXPECT_NEAR(j["median"].get<double>(), 0.45, 1e-12);
  EXPECT_NEAR(j["sse"].get<double>(), 2.85, 1e-12);
  EXPECT_NEAR(j["rmse"].get<double>(), std::sqrt(0.285), 1e-12);
  EXPECT_NEAR(j["std"].get<double>(), 0.1 * std::sqrt(8.25), 1e-12);
  EXPECT_EQ(j["pairs"], 10);
  EXPECT_EQ(j["alignment"], "none");
  EXPECT_EQ(j["pose_relation"], "trans");
}

TEST(EvalCli, ApeSe3AlignmentRemovesARigidMotion) {
  // A non-collinear reference, and the estimate = Rz(90 deg) * ref + (5, -2, 1): aligned, nothing is left.
  TempDir dir;
  std::string r, e;
  for (int i = 0; i < 20; ++i) {
    const double x = std::cos(0.3 * i) * 4, y = std::sin(0.3 * i) * 3, z = 0.1 * i;
    r += tumLine(i * 0.1, x, y, z);
    std::ostringstream s;
    s.precision(17);
    // Rz(90): (x, y, z) -> (-y, x, z); orientation q = (0, 0, sin 45, cos 45).
    s << i * 0.1 << " " << -y + 5 << " " << x - 2 << " " << z + 1 << " 0 0 0.70710678118654752 0.70710678118654752\n";
    e += s.str();
  }
  writeText(dir / "ref.txt", r);
  writeText(dir / "est.txt", e);
  const std::string files = (dir / "ref.txt").string() + " " + (dir / "est.txt").string();
  const CliResult a = runDrover("eval ape " + files + " --align se3 --pose-relation full --json " +
                                (dir / "a.json").string());
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_TRUE(contains(a.output, "(with SE(3) Umeyama alignment)")) << a.output;
  EXPECT_LT(readJson(dir / "a.json")["max"].get<double>(), 1e-9);
  EXPECT_NEAR(readJson(dir / "a.json")["alignment_transform"]["translation"][1].get<double>(), 5.0, 1e-9);  // R^T (-t)
  const CliResult n = runDrover("eval ape " + files + " --json " + (dir / "n.json").string());
  ASSERT_EQ(n.exit_code, 0) << n.output;
  EXPECT_GT(readJson(dir / "n.json")["max"].get<double>(), 1.0);
}

TEST(EvalCli, RpeFramePairsGiveTheHandComputedError) {
  // delta 2 frames: pairs (0, 2), (2, 4), (4, 6), (6, 8); each moves 2 m in the reference and 2.2 m in the estimate.
  LineFixture f;
  const CliResult r = runDrover("eval rpe " + f.files() + " --delta 2 --delta-unit frames");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "for delta = 2 (frames) using consecutive pairs")) << r.output;
  const Json j = readJson(f.json);
  EXPECT_EQ(j["count"], 4);
  EXPECT_NEAR(j["mean"].get<double>(), 0.2, 1e-12);
  EXPECT_NEAR(j["std"].get<double>(), 0.0, 1e-12);
  EXPECT_EQ(j["delta_unit"], "frames");
}

TEST(EvalCli, RpeMeterPairsFollowTheEstimatePathUnlessTheReferenceIsAsked) {
  // delta 2.1 m. Estimate path (1.1 m steps): ids 2, 4, 6, 8 -> 3 pairs of 2 frames, error 0.2 m each.
  // Reference path (1 m steps): ids 3, 6, 9 -> 2 pairs of 3 frames, error 0.3 m each.
  LineFixture f;
  const CliResult e = runDrover("eval rpe " + f.files() + " --delta 2.1 --delta-unit m");
  ASSERT_EQ(e.exit_code, 0) << e.output;
  Json j = readJson(f.json);
  EXPECT_EQ(j["count"], 3);
  EXPECT_NEAR(j["mean"].get<double>(), 0.2, 1e-12);
  EXPECT_EQ(j["pairs_from"], "estimate");
  const CliResult r = runDrover("eval rpe " + f.files() + " --delta 2.1 --delta-unit meters --pairs-from-reference");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  j = readJson(f.json);
  EXPECT_EQ(j["count"], 2);
  EXPECT_NEAR(j["mean"].get<double>(), 0.3, 1e-12);
}

// KITTI poses 1 m apart along z; the estimate is `scale` times longer.
void writeKittiLine(const fs::path& p, int frames, double scale) {
  std::ostringstream s;
  s.precision(17);
  for (int i = 0; i < frames; ++i) s << "1 0 0 0 0 1 0 0 0 0 1 " << scale * i << "\n";
  writeText(p, s.str());
}

TEST(EvalCli, KittiDriftOfAConstantScaleError) {
  // 151 frames (150 m): only 100 m segments fit, starting at frames 0, 10, ..., 40 (last frame f + 101 <= 150).
  // Each has error 0.02 * 101 m over 100 m: t_err = 2.02 %, no rotation error.
  TempDir dir;
  writeKittiLine(dir / "gt.txt", 151, 1.0);
  writeKittiLine(dir / "est.txt", 151, 1.02);
  const CliResult r = runDrover("eval kitti " + (dir / "gt.txt").string() + " " + (dir / "est.txt").string() +
                                " --json " + (dir / "k.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "5 segments")) << r.output;
  const Json j = readJson(dir / "k.json");
  EXPECT_NEAR(j["t_err_percent"].get<double>(), 2.02, 1e-9);
  EXPECT_NEAR(j["r_err_deg_per_100m"].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(j["segments"], 5);
  EXPECT_EQ(j["per_length"][0]["segments"], 5);
  EXPECT_EQ(j["per_length"][1]["segments"], 0);
}

TEST(EvalCli, BadInputExitsWithCodeTwoAndOneClearLine) {
  LineFixture f;
  const std::string files = f.ref.string() + " " + f.est.string();
  CliResult r = runDrover("eval ape " + f.ref.string() + " " + (f.dir / "missing.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "missing.txt")) << r.output;
  r = runDrover("eval ape " + files + " --format bogus");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = runDrover("eval ape " + files + " --align affine");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = runDrover("eval ape " + files + " --t-max-diff -1");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  writeText(f.dir / "empty.txt", "# nothing\n");
  r = runDrover("eval ape " + f.ref.string() + " " + (f.dir / "empty.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  r = runDrover("eval rpe " + files + " --delta 50");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "smaller delta")) << r.output;
  r = runDrover("eval ape " + files + " --plot " + (f.dir / "no" / "such" / "dir.png").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

TEST(EvalCli, TimeOptionsBeyondTheLargestTimeAreErrorsNotAnOverflow) {
  // --t-offset 1e10 overflowed to 0 s in the seconds -> nanoseconds conversion, so every pose "matched".
  LineFixture late(1.0);
  for (const char* option : {"--t-offset", "--t-max-diff"}) {
    const CliResult r = runDrover("eval ape " + late.files() + " " + option + " 1e10");
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, std::string("[error] ") + option + ": 10000000000 s is beyond the largest time"))
        << r.output;
    EXPECT_EQ(countLinesWith(r.output, "[error]"), 1u) << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(late.json));
}

TEST(EvalCli, TooFewMatchesExitWithCodeTwo) {
  LineFixture late(1.0);  // the estimate's clock runs 1 s late: nothing within 10 ms
  CliResult r = runDrover("eval ape " + late.ref.string() + " " + late.est.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "no matching timestamps")) << r.output;
  EXPECT_EQ(countLinesWith(r.output, "[error]"), 1u) << r.output;
  // --t-offset -1 s brings them together again.
  r = runDrover("eval ape " + late.files() + " --t-offset -1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(readJson(late.json)["pairs"], 10);
  // Two matched poses cannot be aligned.
  TempDir dir;
  writeText(dir / "two.txt", tumLine(100.0, 0, 0, 0) + tumLine(100.1, 1, 0, 0));
  r = runDrover("eval ape " + late.ref.string() + " " + (dir / "two.txt").string() + " --align se3");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "two.txt (against ")) << r.output;
  EXPECT_TRUE(contains(r.output, "cannot align (se3): the 2 matched positions are all equal or on one line")) << r.output;
}

TEST(EvalCli, KittiRejectsUnequalCountsAndShortTrajectories) {
  TempDir dir;
  writeKittiLine(dir / "gt.txt", 151, 1.0);
  writeKittiLine(dir / "est.txt", 150, 1.0);
  writeKittiLine(dir / "short.txt", 60, 1.0);
  CliResult r = runDrover("eval kitti " + (dir / "gt.txt").string() + " " + (dir / "est.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "by index")) << r.output;
  r = runDrover("eval kitti " + (dir / "short.txt").string() + " " + (dir / "short.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "no segment")) << r.output;
}

TEST(EvalCli, PlotIsWrittenAsPng) {
  if (std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 with matplotlib not available";
  LineFixture f;
  const fs::path png = f.dir / "ape.png";
  const CliResult r = runDrover("eval ape " + f.files() + " --plot " + png.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG") << r.output;
}

TEST(EvalCli, MissingPythonSkipsThePlotWithOneLineAndStillPrintsTheNumbers) {
  LineFixture f;
  ::setenv("DROVER_PYTHON", "/nonexistent/python3", 1);
  const CliResult r = runDrover("eval ape " + f.files() + " --plot " + (f.dir / "ape.png").string());
  ::unsetenv("DROVER_PYTHON");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(countLinesWith(r.output, "plot"), 1u) << r.output;
  EXPECT_EQ(countLinesWith(r.output, "plot skipped"), 1u) << r.output;
  EXPECT_TRUE(contains(r.output, "      rmse\t")) << r.output;
  EXPECT_FALSE(fs::exists(f.dir / "ape.png"));
  EXPECT_NEAR(readJson(f.json)["mean"].get<double>(), 0.45, 1e-12);
}

TEST(EvalCli, Sim3AlignmentUndoesAScaledKittiSequence) {
  // KITTI 00 ground truth (4541 poses) against itself with every position scaled by 1.01 about the origin:
  // the Sim(3) Umeyama scale is 1 / 1.01 and nothing is left; without alignment the largest error is 1 % of the
  // farthest distance from the origin.
  const fs::path gt = sharedData("kitti/poses/00.txt");
  DROVER_REQUIRE_SHARED(gt);
  TempDir dir;
  Trajectory est = io::readKitti(gt.string());
  double farthest = 0.0;
  for (auto& p : est) {
    farthest = std::max(farthest, p.T_world_body.translation().norm());
    p.T_world_body.translation() *= 1.01;
  }
  io::writeKitti((dir / "est.txt").string(), est);
  const std::string files = gt.string() + " " + (dir / "est.txt").string() + " --format kitti --json ";
  CliResult r = runDrover("eval ape " + files + (dir / "s.json").string() + " --align sim3 --pose-relation full");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json s = readJson(dir / "s.json");
  EXPECT_EQ(s["pairs"], 4541);
  EXPECT_EQ(s["alignment"], "sim3");
  EXPECT_NEAR(s["alignment_transform"]["scale"].get<double>(), 1.0 / 1.01, 1e-9);
  EXPECT_LT(s["max"].get<double>(), 1e-6);
  r = runDrover("eval ape " + files + (dir / "n.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NEAR(readJson(dir / "n.json")["max"].get<double>(), 0.01 * farthest, 1e-6);
}

}  // namespace
}  // namespace drover::test
