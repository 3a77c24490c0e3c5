// `drover features track` end to end on the shared EuRoC snippet: files, keys, figures in sane bounds, errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>

#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const fs::path kEuroc = sharedData("euroc/V1_01_easy_micro");

std::string trackArgs(const fs::path& out, const std::string& extra) {
  return "features track " + kEuroc.string() + " --format euroc --config " + std::string(DROVER_SOURCE_DIR) +
         "/config/euroc.yaml --detector shi-tomasi --out " + out.string() + " " + extra;
}

TEST(FeaturesTrackCli, WritesPerFrameRecordsSummaryAndOverlays) {
  DROVER_REQUIRE_SHARED(kEuroc);
  TempDir dir;
  const CliResult r = runDrover(trackArgs(dir.path(), "--overlay-every 20 --max-frames 60"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "60 frames")) << r.output;
  const auto j = readJson(dir.path() / "tracks.json");
  ASSERT_EQ(j["frames"].size(), 60u);
  for (const char* key :
       {"t", "features", "new", "tracked", "rejected_fb", "rejected_border", "rejected_ransac", "inlier_ratio", "ms"})
    EXPECT_TRUE(j["frames"][0].contains(key)) << key;
  EXPECT_EQ(j["frames"][0]["tracked"], 0) << "nothing to track on the first frame";
  EXPECT_EQ(j["frames"][0]["features"], j["frames"][0]["new"]);
  EXPECT_GT(j["frames"][1]["t"].get<double>(), 0.04);  // 20 Hz
  const auto& s = j["summary"];
  EXPECT_GT(s["mean_features"].get<double>(), 100.0);
  EXPECT_GT(s["mean_track_length"].get<double>(), 5.0);
  EXPECT_GT(s["ransac_inlier_ratio"].get<double>(), 0.9);
  EXPECT_GT(s["fraction_tracked_ge_50"].get<double>(), 0.9);
  EXPECT_GT(s["ms_per_frame"].get<double>(), 0.0);
  for (int k : {0, 20, 40}) {
    char name[32];
    std::snprintf(name, sizeof name, "overlay_%06d.png", k);
    EXPECT_TRUE(fs::exists(dir.path() / name)) << name;
  }
  EXPECT_FALSE(fs::exists(dir.path() / "overlay_000060.png"));
}

TEST(FeaturesTrackCli, StartAndDurationSelectAWindowOfFrames) {
  DROVER_REQUIRE_SHARED(kEuroc);
  TempDir dir;
  const CliResult r = runDrover(trackArgs(dir.path(), "--start 1.0 --duration 1.0 -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(r.output.empty()) << r.output;
  const auto j = readJson(dir.path() / "tracks.json");
  EXPECT_GE(j["frames"].size(), 20u);
  EXPECT_LE(j["frames"].size(), 21u);
  EXPECT_NEAR(j["frames"][0]["t"].get<double>(), 1.0, 0.05);
}

TEST(FeaturesTrackCli, AsyncModeRunsAndRecordsIt) {
  DROVER_REQUIRE_SHARED(kEuroc);
  TempDir dir;
  const CliResult r = runDrover(trackArgs(dir.path(), "--async --max-frames 30 -q"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = readJson(dir.path() / "tracks.json");
  EXPECT_EQ(j["async"], true);
  EXPECT_GT(j["summary"]["mean_features"].get<double>(), 50.0);
}

TEST(FeaturesTrackCli, TheConfigsTrackerSectionReachesTheTracker) {
  DROVER_REQUIRE_SHARED(kEuroc);
  TempDir dir;
  // The shipped EuRoC config with the tracker's cap lowered to 40 (and everything else as shipped).
  std::ifstream in(std::string(DROVER_SOURCE_DIR) + "/config/euroc.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string key = "    max_features: 150";
  const auto at = text.find(key);
  ASSERT_NE(at, std::string::npos) << "config/euroc.yaml has no visual.tracker.max_features line";
  text.replace(at, key.size(), "    max_features: 40");
  const fs::path config = dir.path() / "euroc40.yaml";
  writeText(config, text);
  const CliResult r = runDrover("features track " + kEuroc.string() + " --format euroc --config " + config.string() +
                                " --detector shi-tomasi --max-frames 20 -q --out " + (dir.path() / "o").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = readJson(dir.path() / "o" / "tracks.json");
  EXPECT_EQ(j["max_features"], 40);
  ASSERT_EQ(j["frames"].size(), 20u);
  int most = 0;
  for (const auto& f : j["frames"]) most = std::max(most, f["features"].get<int>());
  EXPECT_EQ(most, 40) << "the cap is reached and never exceeded (the default would give ~150)";
}

TEST(FeaturesTrackCli, BadInputIsOneErrorLineAndExitCode2) {
  TempDir dir;
  CliResult r = runDrover("features track " + (dir.path() / "missing").string() +
                          " --format euroc --detector orb --out " + (dir.path() / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error]")) << r.output;
  DROVER_REQUIRE_SHARED(kEuroc);
  r = runDrover(trackArgs(dir.path(), "--start -1"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--start")) << r.output;
  r = runDrover("features track " + kEuroc.string() + " --format euroc --detector superpoint --weights " +
                (dir.path() / "none.onnx").string() + " --out " + (dir.path() / "o").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "none.onnx")) << r.output;
}

}  // namespace
}  // namespace drover::test
