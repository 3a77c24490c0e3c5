// README.md's promises about bad files -- formats, configs, weights -- each as a test through the binary, quoting
// the sentence it checks (the run-time promises are in test_readme_promises.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz/fixtures.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

// Exit 2 with one [error] line that holds every fragment.
void expectOneError(const CliResult& r, std::initializer_list<std::string> fragments) {
  EXPECT_EQ(r.exit_code, 2) << r.output;
  std::vector<std::string> errors;
  std::istringstream in(r.output);
  for (std::string l; std::getline(in, l);)
    if (contains(l, "[error]")) errors.push_back(l);
  ASSERT_EQ(errors.size(), 1u) << r.output;
  for (const std::string& f : fragments)
    EXPECT_TRUE(contains(errors[0], f)) << "should name " << f << ": " << errors[0];
}

// KITTI table: "`.bin` = float32 x, y, z, reflectance (size must be a multiple of 16 bytes)"
TEST(ReadmePromisesFiles, AKittiScanWhoseSizeIsNotAMultipleOf16BytesIsAnErrorNamingIt) {
  TempDir dir;
  fuzz::writeKittiSequence(dir / "00", 3, 4, 16);
  const std::string bin = readText(dir / "00" / "velodyne" / "000001.bin");
  writeText(dir / "00" / "velodyne" / "000001.bin", bin.substr(0, bin.size() - 3));
  expectOneError(runDrover("info " + (dir / "00").string() + " --format kitti"), {"000001.bin"});
}

class G2oPromise : public ::testing::Test {
 protected:
  // The fixture graph with `line` appended (or, with replace, its first line replaced by it).
  CliResult optimize(const std::string& line, bool replace = false) {
    fuzz::writeG2oGraph(dir_ / "in.g2o");
    std::string g = readText(dir_ / "in.g2o");
    if (replace)
      g = line + "\n" + g.substr(g.find('\n') + 1);
    else
      g += line + "\n";
    writeText(dir_ / "in.g2o", g);
    return runDrover("graph optimize " + (dir_ / "in.g2o").string() + " " + (dir_ / "out.g2o").string());
  }
  TempDir dir_;
};

// g2o table: "unknown tags, wrong field counts, unknown or duplicate ids are errors naming the line"
TEST_F(G2oPromise, UnknownTagsWrongFieldCountsAndUnknownOrDuplicateIdsAreErrorsNamingTheLine) {
  const std::string info = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";
  expectOneError(optimize("VERTEX_SE2 9 0 0 0"), {"in.g2o", "line 15"});
  expectOneError(optimize("VERTEX_SE3:QUAT 9 0 0 0 0 0 0"), {"in.g2o", "line 15"});
  expectOneError(optimize("EDGE_SE3:QUAT 0 42 0 0 0 0 0 0 1" + info), {"in.g2o", "line 15"});
  expectOneError(optimize("VERTEX_SE3:QUAT 3 0 0 0 0 0 0 1"), {"in.g2o", "line 15"});
  EXPECT_FALSE(fs::exists(dir_ / "out.g2o"));
}

// g2o table: "quaternions must be unit to 1e-3"
TEST_F(G2oPromise, AQuaternionFurtherThan1e3FromUnitIsAnErrorNamingTheLine) {
  expectOneError(optimize("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1.01", true), {"in.g2o", "line 1"});
  EXPECT_EQ(optimize("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1.0005", true).exit_code, 0);
}

// "unknown keys and unknown top-level sections are errors naming their line (a typo never passes silently)"
class ConfigPromise : public ::testing::Test {
 protected:
  // info on a small KITTI sequence with `yaml` as its config.
  CliResult info(const std::string& yaml) {
    writeText(dir_ / "c.yaml", yaml);
    return runDrover("info " + (dir_ / "00").string() + " --format kitti --config " + (dir_ / "c.yaml").string());
  }
  void SetUp() override { fuzz::writeKittiSequence(dir_ / "00", 2, 4, 16); }
  TempDir dir_;
};

TEST_F(ConfigPromise, AnUnknownKeyIsAnErrorNamingItsLine) {
  expectOneError(info("dataset:\n  load_images: false\n  kitti_camra: 2\n"), {"c.yaml", "line 3", "kitti_camra"});
}

TEST_F(ConfigPromise, AnUnknownTopLevelSectionIsAnErrorNamingItsLine) {
  expectOneError(info("dataset:\n  load_images: false\nodometri:\n  use_imu: false\n"), {"c.yaml", "line 3"});
}

// Issue 14, item 8: "Duplicate keys take the last value and a duplicate top-level section is ignored".
TEST_F(ConfigPromise, ADuplicateKeyIsAnErrorNamingItsLine) {
  expectOneError(info("dataset:\n  load_images: false\n  load_images: true\n"), {"c.yaml", "line 3", "load_images"});
}

TEST_F(ConfigPromise, ADuplicateTopLevelSectionIsAnErrorNamingItsLine) {
  expectOneError(info("dataset:\n  load_images: false\ndataset:\n  load_lidar: true\n"), {"c.yaml", "line 3"});
}

// Issue 14, item 8: "`--config DIR` (a directory) runs with built-in defaults".
TEST_F(ConfigPromise, AFolderGivenAsTheConfigIsAnErrorNamingIt) {
  expectOneError(runDrover("info " + (dir_ / "00").string() + " --format kitti --config " + dir_.path().string()),
                 {dir_.path().string()});
  expectOneError(runDrover("run " + (dir_ / "00").string() + " --format kitti --config " + dir_.path().string() +
                           " --out " + (dir_ / "r").string()),
                 {dir_.path().string()});
}

// features track: "unknown keys and bad values are errors naming the file and line"
TEST(ReadmePromisesFiles, VisualConfigUnknownKeysAndBadValuesAreErrorsNamingTheFileAndLine) {
  TempDir dir;
  fuzz::writeTexturedPng(dir / "board.png", 64, 48, 1);
  writeText(dir / "typo.yaml", "visual:\n  tracker:\n    max_featurs: 150\n");
  writeText(dir / "bad.yaml", "visual:\n  tracker:\n    max_features: lots\n");
  writeText(dir / "nan.yaml", "visual:\n  tracker:\n    flow_epsilon: .nan\n");
  for (const char* name : {"typo.yaml", "bad.yaml", "nan.yaml"}) {
    SCOPED_TRACE(name);
    expectOneError(runDrover("features detect --detector orb " + (dir / "board.png").string() + " --config " +
                             (dir / name).string()),
                   {name, "line 3"});
  }
}

// features detect: "A missing or malformed file, or a network whose outputs do not have these names and shapes, is
// an error that says so"
TEST(ReadmePromisesFiles, AMissingOrMalformedWeightsFileIsAnErrorNamingIt) {
  TempDir dir;
  fuzz::writeTexturedPng(dir / "board.png", 64, 48, 1);
  writeText(dir / "junk.onnx", "this is no network\n");
  for (const char* name : {"none.onnx", "junk.onnx"}) {
    SCOPED_TRACE(name);
    expectOneError(runDrover("features detect --detector superpoint --weights " + (dir / name).string() + " " +
                             (dir / "board.png").string()),
                   {name});
  }
}

// "Every command prints one line `[error] FILE (RECORD): what is wrong`": a bad value in a shipped config's
// odometry section names the file and the line.
TEST(ReadmePromisesFiles, ABadOdometryValueNamesTheConfigAndItsLine) {
  TempDir dir;
  fuzz::writeKittiSequence(dir / "00", 2, 4, 16);
  std::string yaml = readText(config("kitti.yaml"));
  const std::size_t at = yaml.find("  use_imu: false");
  ASSERT_NE(at, std::string::npos);
  const std::size_t line = static_cast<std::size_t>(std::count(yaml.begin(), yaml.begin() + at, '\n')) + 1;
  yaml.replace(at, 16, "  use_imu: perhaps");
  writeText(dir / "k.yaml", yaml);
  expectOneError(runDrover("run " + (dir / "00").string() + " --format kitti --config " + (dir / "k.yaml").string() +
                           " --out " + (dir / "r").string()),
                 {"k.yaml", "line " + std::to_string(line)});
}

}  // namespace
}  // namespace drover::test
