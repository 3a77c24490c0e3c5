// `drover config import-lvi-sam FILE...`: LVI-SAM's shipped parameter files (tests/fixtures/lvi_sam/) become a
// config on stdout that every loader of `drover run --config` accepts and that drover run runs with; what is not
// imported is listed on stderr and in the config's closing comment block; a bad file is one error line, exit 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "io/config.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/visual/vio_config_io.hpp"
#include "io/visual/visual_config_io.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const fs::path kFixtures = fs::path(DROVER_SOURCE_DIR) / "tests" / "fixtures" / "lvi_sam";

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs the import with stdout and stderr kept apart.
struct ImportRun {
  int exit_code = -1;
  std::string out, err;
};

ImportRun runImport(const TempDir& dir, const std::string& args) {
  const CliResult r = runShell(std::string(DROVER_BINARY) + " config import-lvi-sam " + args + " > " +
                               (dir / "platform.yaml").string() + " 2> " + (dir / "stderr.txt").string());
  return {r.exit_code, slurp(dir / "platform.yaml"), slurp(dir / "stderr.txt")};
}

std::string bothFixtures() {
  return (kFixtures / "params_lidar.yaml").string() + " " + (kFixtures / "params_camera.yaml").string();
}

TEST(ConfigImportCli, LviSamsShippedFilesGiveAConfigEveryRunLoaderAccepts) {
  TempDir dir;
  const ImportRun r = runImport(dir, bothFixtures());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string config = (dir / "platform.yaml").string();
  io::DatasetOptions d;
  ASSERT_NO_THROW(d = io::loadDatasetOptions(config)) << r.out;
  pipeline::OdometryConfig o;
  ASSERT_NO_THROW(o = io::loadOdometryConfig(config)) << r.out;
  ASSERT_NO_THROW(io::loadVisualConfig(config)) << r.out;
  vio::VioConfig v;
  ASSERT_NO_THROW(v = io::loadVioConfig(config)) << r.out;
  EXPECT_EQ(d.lidar_topic, "/points_raw");
  EXPECT_EQ(d.imu_topic, "/imu_raw");
  EXPECT_FALSE(d.load_images) << "the MEI camera cannot be represented";
  EXPECT_EQ(o.layout.n_rings, 16);
  EXPECT_EQ(o.preintegration.acc_noise_density, 3.9939570888238808e-03);
  EXPECT_EQ(o.preintegration.gravity, 9.80511);
  EXPECT_EQ(o.propagator.gravity, 9.80511) << "one gravity for the whole IMU chain";
  EXPECT_FALSE(o.initializer.use_orientation) << "LVI-SAM's extrinsicRPY differs from extrinsicRot";
  EXPECT_EQ(o.loop.min_age, 30.0);
  EXPECT_EQ(o.loop.submap_keyframes, 25);
  EXPECT_EQ(v.max_iterations, 10);
  EXPECT_EQ(v.depth_mode, vio::DepthMode::kFixed);
}

TEST(ConfigImportCli, TheIgnoredParametersGoToStderrAndToTheConfigsClosingComments) {
  TempDir dir;
  const ImportRun r = runImport(dir, bothFixtures());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "not imported:")) << r.err;
  for (const char* key : {"lvi_sam.savePCD --", "model_type -- model_type MEI", "lidar_to_cam_tx --",
                          "vocabulary_file --", "lvi_sam.historyKeyframeFitnessScore --"}) {
    EXPECT_TRUE(contains(r.err, key)) << key << " missing from stderr:\n" << r.err;
    EXPECT_TRUE(contains(r.out, key)) << key << " missing from the config's comments";
  }
  EXPECT_FALSE(contains(r.out, "[info]")) << "stdout holds only the config";
  const ImportRun quiet = runImport(dir, "-q " + bothFixtures());
  EXPECT_EQ(quiet.exit_code, 0);
  EXPECT_EQ(quiet.err, "") << "-q prints only errors";
  EXPECT_EQ(quiet.out, r.out);
}

TEST(ConfigImportCli, DroverRunRunsASimulatedCourseWithTheImportedConfig) {
  TempDir dir;
  ASSERT_EQ(runImport(dir, (kFixtures / "params_lidar.yaml").string()).exit_code, 0);
  const CliResult sim =
      runDrover("sim -q --scenario straight --duration 2 --no-camera --out " + (dir / "straight").string());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const CliResult run = runDrover("run " + (dir / "straight").string() + " --format sim --config " +
                                  (dir / "platform.yaml").string() + " --out " + (dir / "run").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "fusing: lidar + IMU")) << run.output;
  EXPECT_TRUE(fs::exists(dir / "run" / "trajectory.tum"));
}

TEST(ConfigImportCli, AMissingFileIsOneErrorLineOnStderrNamingItWithExit2AndNoConfig) {
  TempDir dir;
  const std::string missing = (dir / "params_lidar.yaml").string();
  const ImportRun r = runImport(dir, missing);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "[error] " + missing + ": parameter file not found\n");
}

TEST(ConfigImportCli, AnUnknownParameterIsListedAndABadValueIsAnErrorNamingFileLineAndKey) {
  TempDir dir;
  writeText(dir / "mine.yaml", "lio_sam:\n  N_SCAN: 32\n  myOwnTweak: 1\n");
  ImportRun r = runImport(dir, (dir / "mine.yaml").string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "lio_sam.myOwnTweak -- not a LIO-SAM / LVI-SAM parameter the importer knows")) << r.err;
  writeText(dir / "bad.yaml", "lio_sam:\n  N_SCAN: 32\n  imuGravity: -9.8\n");
  r = runImport(dir, (dir / "bad.yaml").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_TRUE(contains(r.err, "[error] " + (dir / "bad.yaml").string() + " (line 3, key 'lio_sam.imuGravity')"))
      << r.err;
}

}  // namespace
}  // namespace drover::test
