// Every command that writes checks its output paths before any work: an unusable one (a folder where a file goes, a
// file where a folder goes, a folder that does not exist) is exit code 2 and one `[error] PATH (OPTION): why` line,
// printed before the command reads its input or prints anything else.
#include <gtest/gtest.h>

#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "io/image_file_io.hpp"
#include "support/cli.hpp"
#include "support/cli_process.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const std::string kFarmSimConfig = std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml";

// Inputs shared by the tests: a 1 s simulated dataset, two TUM trajectories, a g2o graph, an image; and the three
// kinds of unusable output path.
class OutputPaths : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    sim_ = runDrover("sim -q --scenario straight --duration 1 --out " + data());
    const std::string tum = "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n3 3 0 0 0 0 0 1\n";
    writeText(*dir_ / "ref.tum", tum);
    writeText(*dir_ / "est.tum", tum);
    writeText(*dir_ / "ref.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
    writeText(*dir_ / "graph.g2o",
              "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0 1\n"
              "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n");
    io::writeImage((*dir_ / "image.png").string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(128)));
    writeText(*dir_ / "a_file", "mine");
    fs::create_directories(*dir_ / "a_folder");
  }
  static void TearDownTestSuite() { dir_.reset(); }
  void SetUp() override { ASSERT_EQ(sim_.exit_code, 0) << sim_.output; }

  static std::string data() { return (*dir_ / "sim").string(); }
  static std::string in(const char* name) { return (*dir_ / name).string(); }
  static std::string folder() { return (*dir_ / "a_folder").string(); }
  static std::string file() { return (*dir_ / "a_file").string(); }
  static std::string missing() { return (*dir_ / "no_such_folder" / "out.json").string(); }

  // One line, exactly `[error] PATH (OPTION): ...why...`, and exit code 2.
  static void expectRefused(const std::string& args, const std::string& path, const std::string& option,
                            const std::string& why) {
    SCOPED_TRACE(args);
    const CliResult r = runDrover(args);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(r.output.rfind("[error] " + path + " (" + option + "): ", 0), 0u) << r.output;
    EXPECT_TRUE(contains(r.output, why)) << why << " missing from: " << r.output;
  }

  static inline std::unique_ptr<TempDir> dir_;
  static inline CliResult sim_;
};

const std::string kIsFolder = "is a folder, not a file";
const std::string kIsFile = "is a file, not a folder";
const std::string kNoFolder = "does not exist";

TEST_F(OutputPaths, RunChecksOut) {
  expectRefused("run " + data() + " --format sim --config " + kFarmSimConfig + " --out " + file(), file(), "--out",
                kIsFile);
  EXPECT_EQ(readText(file()), "mine");
}

TEST_F(OutputPaths, SimChecksOut) {
  expectRefused("sim --scenario straight --duration 1 --out " + file(), file(), "--out", kIsFile);
  const std::string under = file() + "/ds";
  expectRefused("sim --scenario straight --duration 1 --out " + under, under, "--out", "is not a folder");
}

TEST_F(OutputPaths, InfoChecksJsonAndExportGt) {
  const std::string info = "info " + data() + " --format sim ";
  expectRefused(info + "--json " + folder(), folder(), "--json", kIsFolder);
  expectRefused(info + "--export-gt " + missing(), missing(), "--export-gt", kNoFolder);
}

TEST_F(OutputPaths, InfoRefusesExportGtOfADatasetWithoutGroundTruthBeforeStreamingIt) {
  TempDir dir;
  writeText(dir / "00" / "times.txt", "0.0\n0.1\n");
  std::string calib;
  for (const char* key : {"P0", "P1", "P2", "P3"}) calib += std::string(key) + ": 500 0 320 0 0 500 240 0 0 0 1 0\n";
  writeText(dir / "00" / "calib.txt", calib + "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  // Scans that fail when read: the error must come before the streaming reaches them.
  writeText(dir / "00" / "velodyne" / "000000.bin", "7 bytes");
  writeText(dir / "00" / "velodyne" / "000001.bin", "7 bytes");
  writeText(dir / "lidar_only.yaml", "dataset:\n  load_images: false\n");
  const CliResult r = runDrover("info " + (dir / "00").string() + " --format kitti --config " +
                                (dir / "lidar_only.yaml").string() + " --export-gt " + (dir / "gt.tum").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_TRUE(contains(r.output, "has no ground truth to export")) << r.output;
}

TEST_F(OutputPaths, EvalChecksJsonAndPlot) {
  const std::string ape = "eval ape " + in("ref.tum") + " " + in("est.tum");
  expectRefused(ape + " --plot " + folder(), folder(), "--plot", kIsFolder);
  expectRefused(ape + " --json " + missing(), missing(), "--json", kNoFolder);
  const std::string under = file() + "/rpe.json";
  expectRefused("eval rpe " + in("ref.tum") + " " + in("est.tum") + " --json " + under, under, "--json",
                "is not a folder");
  expectRefused("eval kitti " + in("ref.kitti") + " " + in("ref.kitti") + " --json " + folder(), folder(), "--json",
                kIsFolder);
}

TEST_F(OutputPaths, LoopPairAndLoopEvalCheckJson) {
  expectRefused("loop pair " + in("a.bin") + " " + in("b.bin") + " --json " + folder(), folder(), "--json", kIsFolder);
  expectRefused("loop eval " + data() + " --format sim --config " + kFarmSimConfig + " --json " + missing(), missing(),
                "--json", kNoFolder);
}

TEST_F(OutputPaths, GraphOptimizeChecksOutputAndJson) {
  expectRefused("graph optimize " + in("graph.g2o") + " " + folder(), folder(), "output", kIsFolder);
  const std::string out = (*dir_ / "out.g2o").string();
  expectRefused("graph optimize " + in("graph.g2o") + " " + out + " --json " + folder(), folder(), "--json",
                kIsFolder);
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(OutputPaths, FeaturesDetectChecksJsonAndDraw) {
  const std::string detect = "features detect --detector orb " + in("image.png");
  expectRefused(detect + " --json " + folder(), folder(), "--json", kIsFolder);
  const std::string slash = (*dir_ / "drawn.png/").string();
  expectRefused(detect + " --draw " + slash, slash, "--draw", "names a folder, not a file");
}

TEST_F(OutputPaths, FeaturesTrackChecksOut) {
  expectRefused("features track " + data() + " --format sim --detector orb --out " + file(), file(), "--out", kIsFile);
}

}  // namespace
}  // namespace drover::test
