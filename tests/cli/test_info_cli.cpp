// `drover info` end to end on the shared EuRoC and KITTI snippets. Expected figures come from the files themselves
// (counts, stamps) or were computed independently with numpy (path lengths, mean points per scan).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

const fs::path kInfoEuroc = sharedData("euroc/V1_01_easy_micro");
const fs::path kInfoKitti00 = sharedData("kitti/sequences/00");

Json readJson(const fs::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in.good()) << p;
  return Json::parse(in);
}

std::vector<std::string> dataLines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  return lines;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(InfoCli, SummarisesTheEurocSnippet) {
  DROVER_REQUIRE_SHARED(kInfoEuroc);
  TempDir dir;
  const CliResult r = runDrover("info " + kInfoEuroc.string() + " --format euroc --json " + (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "29120 samples")) << r.output;
  EXPECT_TRUE(contains(r.output, "752x480 px")) << r.output;
  const Json j = readJson(dir / "info.json");
  // imu0/data.csv: 29120 rows from 1403715273262142976 to 1403715418857143040 ns.
  EXPECT_EQ(j["imu"]["count"], 29120);
  EXPECT_EQ(j["imu"]["first_time_ns"].get<std::int64_t>(), 1403715273262142976);
  EXPECT_EQ(j["imu"]["last_time_ns"].get<std::int64_t>(), 1403715418857143040);
  EXPECT_NEAR(j["imu"]["mean_rate_hz"].get<double>(), 29119 / 145.595000064, 1e-9);
  // cam0/data.csv: 95 frames, 1403715273262142976 .. 1403715277962142976 ns, i.e. 94 intervals over 4.7 s.
  EXPECT_EQ(j["camera"]["count"], 95);
  EXPECT_NEAR(j["camera"]["mean_rate_hz"].get<double>(), 20.0, 1e-9);
  EXPECT_EQ(j["camera"]["width"], 752);
  EXPECT_EQ(j["camera"]["height"], 480);
  EXPECT_EQ(j["camera"]["channels"], 1);
  EXPECT_EQ(j["lidar"]["count"], 0);
  EXPECT_DOUBLE_EQ(j["calibration"]["camera"]["fx"].get<double>(), 458.654);
  EXPECT_NEAR(j["calibration"]["T_imu_cam"][3].get<double>(), -0.0216401454975, 1e-12);
  // groundtruth_tum.txt: 28712 poses, 1403715274.30214 .. 1403715417.85714 s, numpy path length 58.591730330 m.
  EXPECT_EQ(j["ground_truth"]["count"], 28712);
  EXPECT_EQ(j["ground_truth"]["body_frame"], "imu");
  EXPECT_NEAR(j["ground_truth"]["span_s"].get<double>(), 143.555, 1e-9);
  EXPECT_NEAR(j["ground_truth"]["path_length_m"].get<double>(), 58.591730330076274, 1e-6);
}

TEST(InfoCli, ExportsTheGroundTruthAsTum) {
  DROVER_REQUIRE_SHARED(kInfoEuroc);
  TempDir dir;
  const fs::path tum = dir / "gt.tum";
  const CliResult r = runDrover("info " + kInfoEuroc.string() + " --format euroc --export-gt " + tum.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::vector<std::string> lines = dataLines(tum);
  ASSERT_EQ(lines.size(), 28712u);
  std::istringstream first(lines.front());
  std::string t;
  double x = 0, y = 0, z = 0, qx = 0, qy = 0, qz = 0, qw = 0;
  first >> t >> x >> y >> z >> qx >> qy >> qz >> qw;
  EXPECT_EQ(t, "1403715274.302140000");
  EXPECT_NEAR(x, 0.878612, 1e-12);
  EXPECT_NEAR(y, 2.142470, 1e-12);
  EXPECT_NEAR(z, 0.947262, 1e-12);
  // Same rotation as the source line (q and -q are equal): |<q, q_source>| = 1.
  const double dot = qx * -0.828459 + qy * -0.058956 + qz * -0.553641 + qw * 0.060514;
  EXPECT_NEAR(std::abs(dot), 1.0, 1e-5);
}

TEST(InfoCli, HonoursTheConfigFile) {
  DROVER_REQUIRE_SHARED(kInfoEuroc);
  TempDir dir;
  writeText(dir / "no_images.yaml", "dataset:\n  load_images: false\n");
  const CliResult r = runDrover("info " + kInfoEuroc.string() + " --format euroc --config " +
                                (dir / "no_images.yaml").string() + " --json " + (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(dir / "info.json");
  EXPECT_EQ(j["camera"]["count"], 0);
  EXPECT_EQ(j["imu"]["count"], 29120);
}

TEST(InfoCli, SummarisesTenKittiFrames) {
  DROVER_REQUIRE_SHARED(kInfoKitti00);
  // The snippet lists all 4541 frames in times.txt but holds only the first 10 scans, so build a 10-frame
  // sequence that links to them (times.txt and poses.txt cut to 10 lines).
  TempDir dir;
  const fs::path seq = dir / "00";
  fs::create_directories(seq / "velodyne");
  fs::create_directories(seq / "image_2");
  for (int i = 0; i < 10; ++i) {
    char buf[16];
    std::snprintf(buf, sizeof(buf), "%06d", i);
    const std::string name(buf);
    fs::create_symlink(kInfoKitti00 / "velodyne" / (name + ".bin"), seq / "velodyne" / (name + ".bin"));
    fs::create_symlink(kInfoKitti00 / "image_2" / (name + ".png"), seq / "image_2" / (name + ".png"));
  }
  fs::copy_file(kInfoKitti00 / "calib.txt", seq / "calib.txt");
  for (const char* file : {"times.txt", "poses.txt"}) {
    std::ifstream in(kInfoKitti00 / file);
    std::ofstream out(seq / file);
    std::string line;
    for (int i = 0; i < 10 && std::getline(in, line); ++i) out << line << "\n";
  }
  const CliResult r = runDrover("info " + seq.string() + " --format kitti --json " + (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(dir / "info.json");
  EXPECT_EQ(j["imu"]["count"], 0);
  EXPECT_EQ(j["lidar"]["count"], 10);
  EXPECT_EQ(j["lidar"]["first_time_ns"].get<std::int64_t>(), 0);
  EXPECT_EQ(j["lidar"]["last_time_ns"].get<std::int64_t>(), 933146700);  // times.txt line 10: 9.331467e-01
  EXPECT_NEAR(j["lidar"]["mean_rate_hz"].get<double>(), 9 / 0.9331467, 1e-9);
  // Mean of the .bin sizes / 16 bytes per point: (124668 + ... + 121357) / 10.
  EXPECT_NEAR(j["lidar"]["mean_points_per_scan"].get<double>(), 123542.9, 1e-9);
  EXPECT_EQ(j["lidar"]["scans_with_time"], 0);
  EXPECT_EQ(j["lidar"]["scans_with_ring"], 0);
  EXPECT_EQ(j["camera"]["count"], 10);
  EXPECT_EQ(j["camera"]["width"], 1241);
  EXPECT_EQ(j["camera"]["height"], 376);
  EXPECT_EQ(j["camera"]["channels"], 3);
  EXPECT_EQ(j["ground_truth"]["count"], 10);
  EXPECT_EQ(j["ground_truth"]["body_frame"], "lidar");
  // numpy: lidar positions of Tr^-1 * T_cam0(i) * Tr over the first 10 poses.
  EXPECT_NEAR(j["ground_truth"]["path_length_m"].get<double>(), 7.738659335084388, 1e-6);
}

TEST(InfoCli, MaxFramesReadsTheSnippetInPlaceAndWithoutItTheMissingScanIsNamed) {
  DROVER_REQUIRE_SHARED(kInfoKitti00);
  TempDir dir;
  const CliResult ok = runDrover("info " + kInfoKitti00.string() + " --format kitti --max-frames 10 --json " +
                                 (dir / "info.json").string());
  ASSERT_EQ(ok.exit_code, 0) << ok.output;
  const Json j = readJson(dir / "info.json");
  EXPECT_EQ(j["lidar"]["count"], 10);
  EXPECT_EQ(j["camera"]["count"], 10);
  EXPECT_EQ(j["lidar"]["last_time_ns"].get<std::int64_t>(), 933146700);
  // times.txt lists 4541 frames but the snippet stops at 000009.bin: reading all of it is an error at frame 10.
  const CliResult bad = runDrover("info " + kInfoKitti00.string() + " --format kitti");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("000010.bin (frame 10)"), std::string::npos) << bad.output;
}

TEST(InfoCli, MissingDatasetExitsWith2NamingThePath) {
  TempDir dir;
  const std::string missing = (dir / "no_such_sequence").string();
  const CliResult r = runDrover("info " + missing + " --format euroc");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, missing)) << r.output;
}

TEST(InfoCli, UnknownFormatExitsWith2) {
  TempDir dir;
  const CliResult r = runDrover("info " + dir.path().string() + " --format tum");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "tum")) << r.output;
}

TEST(InfoCli, ConfigWithATypoExitsWith2NamingTheKey) {
  DROVER_REQUIRE_SHARED(kInfoEuroc);
  TempDir dir;
  writeText(dir / "typo.yaml", "dataset:\n  load_imgs: false\n");
  const CliResult r =
      runDrover("info " + kInfoEuroc.string() + " --format euroc --config " + (dir / "typo.yaml").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "dataset.load_imgs")) << r.output;
}

TEST(InfoCli, ExportingMissingGroundTruthExitsWith2) {
  DROVER_REQUIRE_SHARED(kInfoEuroc);
  // A copy of the sequence's mav0 without any ground truth, by linking only imu0 and cam0.
  TempDir dir;
  fs::create_directories(dir / "seq" / "mav0");
  fs::create_directory_symlink(kInfoEuroc / "mav0" / "imu0", dir / "seq" / "mav0" / "imu0");
  fs::create_directory_symlink(kInfoEuroc / "mav0" / "cam0", dir / "seq" / "mav0" / "cam0");
  const CliResult r = runDrover("info " + (dir / "seq").string() + " --format euroc --export-gt " +
                                (dir / "gt.tum").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "no ground truth")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "gt.tum"));
}

}  // namespace
}  // namespace drover::test
