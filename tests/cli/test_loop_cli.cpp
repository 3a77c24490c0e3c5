// `drover loop pair` on the real KITTI revisit / non-revisit pairs and `drover loop eval` on a short simulated course
// (mode A) and on pair lists written by the tests over the shared KITTI scans (mode B); bad inputs exit 2 with one
// line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

const std::string kSimConfig = std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml";

TEST(LoopPairCli, RevisitOf08IsTheSamePlaceTurnedBy148Degrees) {
  const fs::path dir = sharedData("kitti/revisit_08");
  DROVER_REQUIRE_SHARED(dir);
  TempDir tmp;
  const CliResult r = runDrover("loop pair -q " + (dir / "000720.bin").string() + " " + (dir / "001500.bin").string() +
                                " --json " + (tmp / "pair.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(tmp / "pair.json");
  for (const char* key : {"distance", "shift", "yaw_deg", "same_place", "icp"}) EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["same_place"].get<bool>()) << j.dump(2);
  EXPECT_NEAR(j["yaw_deg"].get<double>(), -148.5, 6.0);
  EXPECT_LT(j["distance"].get<double>(), j["threshold"].get<double>());
}

TEST(LoopPairCli, NonRevisitOf00IsNotTheSamePlace) {
  const fs::path dir = sharedData("kitti/non_revisit_00");
  DROVER_REQUIRE_SHARED(dir);
  TempDir tmp;
  const CliResult r = runDrover("loop pair -q " + (dir / "000094.bin").string() + " " + (dir / "000198.bin").string() +
                                " --json " + (tmp / "pair.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(tmp / "pair.json");
  EXPECT_FALSE(j["same_place"].get<bool>()) << j.dump(2);
  EXPECT_GE(j["distance"].get<double>(), j["threshold"].get<double>());
  EXPECT_TRUE(j.contains("icp"));
}

TEST(LoopPairCli, MissingScanOrTruncatedBinIsOneLineErrorWithExitCode2) {
  TempDir tmp;
  const fs::path good = tmp / "good.bin", bad = tmp / "bad.bin";
  writeText(good, std::string(16 * 200, '\0'));
  writeText(bad, std::string(16 * 200 + 7, '\0'));
  CliResult r = runDrover("loop pair " + good.string() + " " + (tmp / "missing.bin").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "missing.bin")) << r.output;
  r = runDrover("loop pair " + good.string() + " " + bad.string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "bad.bin")) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

// A KITTI-like sequence folder: revisit_08's two scans as frames 0 and 1, non_revisit_00's as 2 and 3.
fs::path kittiPairsFolder(const TempDir& tmp) {
  const fs::path seq = tmp / "seq";
  fs::create_directories(seq / "velodyne");
  fs::copy_file(sharedData("kitti/revisit_08/000720.bin"), seq / "velodyne/000000.bin");
  fs::copy_file(sharedData("kitti/revisit_08/001500.bin"), seq / "velodyne/000001.bin");
  fs::copy_file(sharedData("kitti/non_revisit_00/000094.bin"), seq / "velodyne/000002.bin");
  fs::copy_file(sharedData("kitti/non_revisit_00/000198.bin"), seq / "velodyne/000003.bin");
  return seq;
}

TEST(LoopEvalCli, PairsModeCountsTheRevisitAsTpAndTheNonRevisitAsTn) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/revisit_08"));
  DROVER_REQUIRE_SHARED(sharedData("kitti/non_revisit_00"));
  TempDir tmp;
  const fs::path seq = kittiPairsFolder(tmp);
  writeText(tmp / "pairs.txt", "0 1 1\n000002 000003 0\n\n");
  const CliResult r = runDrover("loop eval -q " + seq.string() + " --format kitti --pairs " +
                                (tmp / "pairs.txt").string() + " --json " + (tmp / "eval.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(tmp / "eval.json");
  EXPECT_EQ(j["queries"], 2);
  EXPECT_EQ(j["true_revisits"], 1);
  EXPECT_EQ(j["tp"], 1);
  EXPECT_EQ(j["fp"], 0);
  EXPECT_EQ(j["fn"], 0);
  EXPECT_EQ(j["tn"], 1);
  EXPECT_DOUBLE_EQ(j["precision"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["recall"].get<double>(), 1.0);
  EXPECT_FALSE(j["curve"].empty());
  // Without the lateral augmentation the revisit (0.22 plain) is missed at the default threshold.
  const CliResult plain = runDrover("loop eval -q " + seq.string() + " --pairs " + (tmp / "pairs.txt").string() +
                                    " --no-augment --json " + (tmp / "plain.json").string());
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_EQ(readJson(tmp / "plain.json")["tp"], 0);
}

TEST(LoopEvalCli, PairsModeRejectsMalformedLinesAndMissingScansNamingTheLine) {
  DROVER_REQUIRE_SHARED(sharedData("kitti/revisit_08"));
  DROVER_REQUIRE_SHARED(sharedData("kitti/non_revisit_00"));
  TempDir tmp;
  const fs::path seq = kittiPairsFolder(tmp);
  writeText(tmp / "bad.txt", "0 1 1\n0 x 1\n");
  CliResult r = runDrover("loop eval " + seq.string() + " --pairs " + (tmp / "bad.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "line 2")) << r.output;
  writeText(tmp / "missing.txt", "0 1 1\n0 7 0\n");
  r = runDrover("loop eval " + seq.string() + " --pairs " + (tmp / "missing.txt").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "line 2") && contains(r.output, "000007.bin")) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

TEST(LoopEvalCli, CourseModeRejectsAMissingDatasetAndOneWithoutGroundTruth) {
  TempDir tmp;
  CliResult r = runDrover("loop eval " + (tmp / "nothing").string() + " --format sim --config " + kSimConfig);
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "nothing")) << r.output;
  // A KITTI odometry sequence without poses (number 11: its poses are not published).
  const fs::path seq00 = sharedData("kitti/sequences/00");
  DROVER_REQUIRE_SHARED(seq00);
  const fs::path seq = tmp / "sequences/11";
  fs::create_directories(seq / "velodyne");
  for (const char* f : {"calib.txt", "times.txt", "velodyne/000000.bin", "velodyne/000001.bin"})
    fs::copy_file(seq00 / f, seq / f);
  r = runDrover("loop eval " + seq.string() + " --format kitti --max-frames 2");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "no ground truth")) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
}

// The overlap scenario drives a course whose second half runs over the first.
TEST(LoopEvalCli, CourseModeOnASimulatedOverlapFindsRevisitsWithoutFalsePositives) {
  TempDir tmp;
  const fs::path sim = tmp / "overlap";
  const CliResult g = runDrover("sim -q --scenario overlap --no-camera --duration 0 --out " + sim.string());
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const CliResult r = runDrover("loop eval -q " + sim.string() + " --format sim --config " + kSimConfig + " --json " +
                                (tmp / "eval.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(tmp / "eval.json");
  for (const char* key : {"precision", "recall", "f1", "threshold", "queries", "true_revisits", "tp", "fp", "fn",
                          "curve", "narrowed_equals_full", "descriptor_ms", "query_ms"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_GT(j["true_revisits"].get<int>(), 0);
  EXPECT_GT(j["recall"].get<double>(), 0.0);
  EXPECT_LE(j["recall"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(j["precision"].get<double>(), 1.0);
  for (const Json& p : j["curve"]) {
    EXPECT_GE(p["precision"].get<double>(), 0.0);
    EXPECT_LE(p["precision"].get<double>(), 1.0);
    EXPECT_GE(p["recall"].get<double>(), 0.0);
    EXPECT_LE(p["recall"].get<double>(), 1.0);
  }
}

// Each accepted loop in report.json says how sure the verifier claims to be (the factor's sigmas) and, with ground
// truth, how far off it was in those sigmas (NEES over 6 DoF; about 6 on average when the claim is honest). With the
// verifier's floors dominating, the NEES is the pose error over the reported sigmas, squared and summed.
TEST(LoopRunReport, EveryAcceptedLoopCarriesItsClaimedSigmasAndItsErrorNormalisedByThem) {
  TempDir tmp;
  const fs::path sim = tmp / "overlap";
  const CliResult g = runDrover("sim -q --scenario overlap --no-camera --duration 0 --out " + sim.string());
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const CliResult r = runDrover("run -q " + sim.string() + " --format sim --config " + kSimConfig +
                                " --no-camera --out " + (tmp / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json loops = readJson(tmp / "run" / "report.json")["loops"];
  int accepted = 0;
  double nees_sum = 0;
  for (const Json& e : loops["events"]) {
    if (!e["accepted"].get<bool>()) continue;
    ++accepted;
    const double sp = e["sigma_position_m"], sr = e["sigma_rotation_deg"];
    EXPECT_GE(sp, 0.05) << "the verifier's position floor";
    EXPECT_GE(sr, 0.005 * 180 / M_PI) << "the verifier's rotation floor";
    const double et = e["pose_error_m"], er = e["pose_error_deg"], nees = e["nees"];
    const double expected = (et / sp) * (et / sp) + (er / sr) * (er / sr);
    EXPECT_NEAR(nees, expected, 0.1 * expected + 0.01) << "loop at " << e["t_query"];
    nees_sum += nees;
  }
  ASSERT_GE(accepted, 3) << "the overlap course closes loops";
  EXPECT_LT(nees_sum / accepted, 6.0) << "on a clean course the verifier's sigmas are not overconfident";
}

}  // namespace
}  // namespace drover::test
