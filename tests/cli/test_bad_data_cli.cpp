// The README's promises about bad data, end to end: what a run drops with a counted warning (non-finite points,
// stamps that do not advance) and what is an error in the `[error] FILE (RECORD): what is wrong` form.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "io/fixtures/bag_fixtures.hpp"
#include "support/cli.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;

const fs::path kKitti00 = sharedData("kitti/sequences/00");

// The first `frames` frames of KITTI 00 (scans, colour images, calib, times) copied into `dir`/00.
fs::path copyKitti00(const TempDir& dir, int frames) {
  const fs::path seq = dir / "00";
  fs::create_directories(seq / "velodyne");
  fs::create_directories(seq / "image_2");
  fs::copy_file(kKitti00 / "calib.txt", seq / "calib.txt");
  std::ifstream times(kKitti00 / "times.txt");
  std::ofstream out(seq / "times.txt");
  std::string line;
  for (int i = 0; i < frames && std::getline(times, line); ++i) out << line << "\n";
  for (int i = 0; i < frames; ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d", i);
    fs::copy_file(kKitti00 / "velodyne" / (std::string(name) + ".bin"), seq / "velodyne" / (std::string(name) + ".bin"));
    fs::copy_file(kKitti00 / "image_2" / (std::string(name) + ".png"), seq / "image_2" / (std::string(name) + ".png"));
  }
  return seq;
}

// Appends `n` points with a NaN coordinate to a KITTI .bin.
void appendNanPoints(const fs::path& bin, int n) {
  std::ofstream f(bin, std::ios::binary | std::ios::app);
  const float nan = std::numeric_limits<float>::quiet_NaN(), one = 1.0f;
  for (int i = 0; i < n; ++i) {
    f.write(reinterpret_cast<const char*>(&one), 4);
    f.write(reinterpret_cast<const char*>(&nan), 4);
    f.write(reinterpret_cast<const char*>(&one), 4);
    f.write(reinterpret_cast<const char*>(&one), 4);
  }
}

TEST(BadDataCli, InfoDropsNanPointsOfAKittiScanWithAWarningAndCountsThem) {
  DROVER_REQUIRE_SHARED(kKitti00);
  TempDir dir;
  const fs::path seq = copyKitti00(dir, 2);
  appendNanPoints(seq / "velodyne" / "000001.bin", 3);
  const CliResult r = runDrover("info " + seq.string() + " --format kitti --json " + (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "[warning] 3 non-finite lidar points dropped (in 1 of 2 scans)")) << r.output;
  EXPECT_EQ(readJson(dir / "info.json")["lidar"]["points_nonfinite_dropped"].get<int>(), 3);
}

TEST(BadDataCli, RunDropsNanPointsOfAKittiScanWithAWarningAndCountsThemInTheReport) {
  DROVER_REQUIRE_SHARED(kKitti00);
  TempDir dir;
  const fs::path seq = copyKitti00(dir, 3);
  appendNanPoints(seq / "velodyne" / "000001.bin", 2);
  const CliResult r = runDrover("run " + seq.string() + " --format kitti --no-loop --out " + (dir / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "[warning] sweep at 0.104 s: 2 non-finite points dropped")) << r.output;
  const nlohmann::json counts = readJson(dir / "run" / "report.json")["counts"];
  EXPECT_EQ(counts["points_nonfinite"].get<int>(), 2);
  EXPECT_EQ(counts["scans_processed"].get<int>(), 3);
  EXPECT_EQ(counts["measurements_dropped"].get<int>(), 0);
}

TEST(BadDataCli, InfoDropsAnImuRowWhoseStampRepeatsWithAWarningNamingTheLineAndCountsIt) {
  const fs::path euroc = sharedData("euroc/V1_01_easy_micro");
  DROVER_REQUIRE_SHARED(euroc);
  TempDir dir;
  const fs::path mav0 = dir / "seq" / "mav0";
  fs::create_directories(mav0 / "imu0");
  fs::create_directories(mav0 / "cam0" / "data");
  fs::copy_file(euroc / "mav0" / "imu0" / "sensor.yaml", mav0 / "imu0" / "sensor.yaml");
  fs::copy_file(euroc / "mav0" / "cam0" / "sensor.yaml", mav0 / "cam0" / "sensor.yaml");
  writeText(mav0 / "cam0" / "data.csv", "#timestamp [ns],filename\n");
  std::string imu = readText(euroc / "mav0" / "imu0" / "data.csv");
  const std::size_t row2 = imu.find('\n', imu.find('\n') + 1) + 1;  // line 3 repeats line 2
  imu.insert(row2, imu.substr(imu.find('\n') + 1, row2 - imu.find('\n') - 1));
  writeText(mav0 / "imu0" / "data.csv", imu);
  const CliResult r = runDrover("info " + (dir / "seq").string() + " --format euroc --json " +
                                (dir / "info.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "[warning] " + (mav0 / "imu0" / "data.csv").string() +
                                     " (line 3): dropped: timestamp 1403715273.262142976 s repeats the previous one"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "Dropped:     1 measurements")) << r.output;
  EXPECT_EQ(readJson(dir / "info.json")["measurements_dropped"].get<int>(), 1);
}

TEST(BadDataCli, RunOnASimulatedDatasetDropsARepeatedScanStampAndANanPointWithWarningsAndCountsThem) {
  TempDir dir;
  const fs::path sim = dir / "sim";
  ASSERT_EQ(runDrover("sim -q --scenario straight --duration 1.5 --no-camera --out " + sim.string()).exit_code, 0);
  std::string index = readText(sim / "lidar" / "timestamps.csv");
  const std::size_t row = index.find("\n2,200000000,") + 1;
  index.replace(row, 11, "2,100000000");  // scan 2 repeats scan 1's stamp
  writeText(sim / "lidar" / "timestamps.csv", index);
  {
    std::fstream f(sim / "lidar" / "000004.bin", std::ios::binary | std::ios::in | std::ios::out);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    f.write(reinterpret_cast<const char*>(&nan), 4);  // point 0's x
  }
  const CliResult r = runDrover("run " + sim.string() + " --format sim --no-loop --config " DROVER_SOURCE_DIR
                                "/config/farm_sim.yaml --out " + (dir / "run").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "[warning] " + (sim / "lidar" / "timestamps.csv").string() +
                                     " (line 4): dropped: timestamp 0.100000000 s repeats the previous one"))
      << r.output;
  EXPECT_TRUE(contains(r.output, ": 1 non-finite points dropped")) << r.output;
  const nlohmann::json counts = readJson(dir / "run" / "report.json")["counts"];
  EXPECT_EQ(counts["measurements_dropped"].get<int>(), 1);
  EXPECT_EQ(counts["points_nonfinite"].get<int>(), 1);
}

TEST(BadDataCli, BagFormatOnAFolderSaysItIsAFolder) {
  TempDir dir;
  const CliResult r = runDrover("info " + dir.path().string() + " --format bag");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error] " + dir.path().string() + ": is a folder, not a ROS bag file")) << r.output;
}

TEST(BadDataCli, EvalOfATrajectoryThatCannotBeAlignedNamesTheFilesAndWhy) {
  TempDir dir;
  writeText(dir / "ref.tum", "1 0 0 0 0 0 0 1\n2 1 0 0 0 0 0 1\n3 2 0 0 0 0 0 1\n");  // on a line
  writeText(dir / "est.tum", "1 5 5 5 0 0 0 1\n2 5 5 5 0 0 0 1\n3 5 5 5 0 0 0 1\n");  // all identical
  for (const char* align : {"se3", "sim3"}) {
    const CliResult r = runDrover("eval ape " + (dir / "ref.tum").string() + " " + (dir / "est.tum").string() +
                                  " --align " + align);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "[error] " + (dir / "est.tum").string() + " (against " +
                                       (dir / "ref.tum").string() + "): cannot align (" + align +
                                       "): the 3 matched positions are all equal or on one line"))
        << r.output;
  }
  writeText(dir / "est.tum", "# nothing\n");
  const CliResult r = runDrover("eval ape " + (dir / "ref.tum").string() + " " + (dir / "est.tum").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error] " + (dir / "est.tum").string() + ": no poses")) << r.output;
}

TEST(BadDataCli, LoopPairOnAnEmptyScanNamesTheScan) {
  DROVER_REQUIRE_SHARED(kKitti00);
  TempDir dir;
  writeText(dir / "empty.bin", "");
  const fs::path good = kKitti00 / "velodyne" / "000000.bin";
  const CliResult r = runDrover("loop pair " + good.string() + " " + (dir / "empty.bin").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error] " + (dir / "empty.bin").string() + ": 0 valid points, fewer than min_points"))
      << r.output;
}

TEST(BadDataCli, PngWhoseHeaderClaimsAHugeImageIsRefusedNamingTheFileNotWithOpenCvsAssertion) {
  TempDir dir;
  // Signature and an IHDR claiming 100000 x 100000 px, 8-bit grey; nothing after it is needed.
  const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R',
                               0, 1, 0x86, 0xa0, 0, 1, 0x86, 0xa0, 8, 0, 0, 0, 0, 0, 0, 0, 0};
  std::ofstream(dir / "huge.png", std::ios::binary).write(reinterpret_cast<const char*>(png), sizeof(png));
  const CliResult r = runDrover("features detect " + (dir / "huge.png").string() + " --detector orb");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error] " + (dir / "huge.png").string() +
                                     " (header): header claims 100000x100000 px, more than"))
      << r.output;
  EXPECT_FALSE(contains(r.output, "CV_IO_MAX_IMAGE_PIXELS")) << r.output;
  // A JPEG whose frame header (SOF0, after an APP0 segment) claims 60000 x 50000 px.
  const unsigned char jpeg[] = {0xff, 0xd8, 0xff, 0xe0, 0, 4, 'J', 'F', 0xff, 0xc0, 0, 17, 8, 0xc3, 0x50, 0xea, 0x60,
                                1, 1, 0x11, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  std::ofstream(dir / "huge.jpg", std::ios::binary).write(reinterpret_cast<const char*>(jpeg), sizeof(jpeg));
  const CliResult j = runDrover("features detect " + (dir / "huge.jpg").string() + " --detector orb");
  EXPECT_EQ(j.exit_code, 2) << j.output;
  EXPECT_TRUE(contains(j.output, "huge.jpg (header): header claims 60000x50000 px, more than")) << j.output;
}

TEST(BadDataCli, FeaturesTrackOnAnImageOfAnotherSizeThanTheCalibrationNamesTheImage) {
  TempDir dir;
  // The fixture bag's /cam/png images are 7x5 px; the config says 8x5.
  writeText(dir / "cfg.yaml", R"(dataset:
  image_topic: /cam/png
  load_lidar: false
  load_imu: false
calibration:
  T_imu_lidar: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
  T_imu_cam: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
  camera: {width: 8, height: 5, fx: 5, fy: 5, cx: 3, cy: 2, distortion_model: none, distortion_coeffs: []}
  lidar_time_offset: 0
  camera_time_offset: 0
)");
  const std::string bag = BagFixtures::get().bag("none").string();
  const CliResult r = runDrover("features track " + bag + " --format bag --detector orb --config " +
                                (dir / "cfg.yaml").string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "[error] " + bag + ":/cam/png#0: image is 7x5 px but the camera calibration says 8x5"))
      << r.output;
}

TEST(BadDataCli, FeaturesTrackWarnsAboutAnImageWhoseStampRepeats) {
  const fs::path euroc = sharedData("euroc/V1_01_easy_micro");
  DROVER_REQUIRE_SHARED(euroc);
  TempDir dir;
  const fs::path mav0 = dir / "seq" / "mav0";
  fs::create_directories(mav0 / "imu0");
  fs::create_directories(mav0 / "cam0" / "data");
  fs::copy_file(euroc / "mav0" / "imu0" / "sensor.yaml", mav0 / "imu0" / "sensor.yaml");
  fs::copy_file(euroc / "mav0" / "cam0" / "sensor.yaml", mav0 / "cam0" / "sensor.yaml");
  writeText(mav0 / "imu0" / "data.csv", "1,0,0,0,0,0,9.8\n");
  std::ifstream rows(euroc / "mav0" / "cam0" / "data.csv");
  std::string header, line, csv;
  std::getline(rows, header);
  for (int i = 0; i < 3 && std::getline(rows, line); ++i) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string name = line.substr(line.find(',') + 1);
    fs::copy_file(euroc / "mav0" / "cam0" / "data" / name, mav0 / "cam0" / "data" / name);
    csv += line + "\n";
    if (i == 1) csv += line + "\n";  // line 4 repeats line 3
  }
  writeText(mav0 / "cam0" / "data.csv", header + "\n" + csv);
  const CliResult r = runDrover("features track " + (dir / "seq").string() + " --format euroc --detector orb --out " +
                                (dir / "out").string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "[warning] " + (mav0 / "cam0" / "data.csv").string() + " (line 4): dropped: timestamp"))
      << r.output;
}

TEST(BadDataCli, InfoRefusesAZeroFocalLengthNamingTheCalibLine) {
  DROVER_REQUIRE_SHARED(kKitti00);
  TempDir dir;
  const fs::path seq = copyKitti00(dir, 1);
  std::string calib = readText(seq / "calib.txt");
  const std::size_t p2 = calib.find("P2: ");
  calib.replace(p2, calib.find('\n', p2) - p2, "P2: 0 0 0 0 0 0 0 0 0 0 0 0");
  writeText(seq / "calib.txt", calib);
  const CliResult r = runDrover("info " + seq.string() + " --format kitti");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "calib.txt (line 3): key 'P2': focal lengths must be > 0 px")) << r.output;
}

}  // namespace
}  // namespace drover::test
