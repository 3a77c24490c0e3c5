// `drover sim` end to end: generate a short scenario, read it back with `drover info --format sim`; bad arguments
// exit 2 with one clear line.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;


TEST(SimCli, GeneratesADatasetThatInfoReadsWithTheExpectedCounts) {
  TempDir dir;
  const fs::path out = dir / "straight";
  const CliResult r = runDrover("sim --scenario straight --duration 1 --seed 3 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "sim-s/s")) << r.output;
  const CliResult info = runDrover("info " + out.string() + " --format sim --json " + (dir / "info.json").string());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const Json scenario = readJson(out / "scenario.json");
  const double d = scenario["duration_s"].get<double>();  // the trajectory's span [s]
  EXPECT_NEAR(d, 1.0, 0.5);
  EXPECT_EQ(scenario["seed"], 3);
  const Json j = readJson(dir / "info.json");
  // IMU at 200 Hz over [0, d]; sweeps of 0.1 s that end by d; 15 Hz frames whose 10 ms exposure ends by d.
  EXPECT_EQ(j["imu"]["count"].get<int>(), static_cast<int>(std::floor(d * 200 + 1e-9)) + 1);
  EXPECT_EQ(j["lidar"]["count"].get<int>(), static_cast<int>(std::floor(d * 10 + 1e-9)));
  EXPECT_EQ(j["camera"]["count"].get<int>(), static_cast<int>(std::floor((d - 0.01) * 15 + 1e-9)) + 1);
  EXPECT_NEAR(j["imu"]["mean_rate_hz"].get<double>(), 200.0, 1e-6);
  EXPECT_EQ(j["lidar"]["scans_with_time"], j["lidar"]["count"]);
  EXPECT_EQ(j["lidar"]["scans_with_ring"], j["lidar"]["count"]);
  EXPECT_GT(j["lidar"]["mean_points_per_scan"].get<double>(), 1000.0);
  EXPECT_EQ(j["camera"]["width"], 640);
  EXPECT_EQ(j["camera"]["height"], 480);
  EXPECT_EQ(j["ground_truth"]["body_frame"], "imu");
  EXPECT_EQ(j["ground_truth"]["count"], j["imu"]["count"]);  // both 200 Hz over the same span
  EXPECT_NEAR(j["calibration"]["camera_time_offset_s"].get<double>(), 0.005, 1e-12);
  EXPECT_NEAR(j["calibration"]["T_imu_lidar"][11].get<double>(), 0.30, 1e-12);  // lidar 0.30 m above the IMU
  EXPECT_FALSE(fs::exists(dir / "straight.partial"));
}

TEST(SimCli, LidarModelAndNoCameraAreHonoured) {
  TempDir dir;
  const fs::path out = dir / "ds";
  const CliResult r =
      runDrover("sim -q --scenario straight --duration 1 --lidar hdl64 --no-camera --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(r.output, "") << "-q prints nothing on success";
  const Json scenario = readJson(out / "scenario.json");
  EXPECT_EQ(scenario["lidar_model"], "hdl64");
  EXPECT_EQ(scenario["sensors"]["camera"], false);
  const CliResult info = runDrover("info " + out.string() + " --format sim --json " + (dir / "info.json").string());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const Json j = readJson(dir / "info.json");
  EXPECT_EQ(j["camera"]["count"], 0);
  EXPECT_GT(j["lidar"]["count"].get<int>(), 0);
}

TEST(SimCli, FaultsAreWrittenIntoScenarioJsonAndBadOnesExitWithCode2NamingTheOption) {
  TempDir dir;
  const fs::path out = dir / "faults";
  const CliResult r = runDrover("sim -q --scenario straight --duration 3 --no-camera --fault imu-gap@1+0.5 "
                                "--fault lidar-dropout@2+0.25 --out " + out.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Json j = readJson(out / "scenario.json");
  ASSERT_EQ(j["faults"].size(), 2u);
  EXPECT_EQ(j["faults"][0]["kind"], "imu-gap");
  EXPECT_EQ(j["faults"][0]["end_ns"].get<std::int64_t>() - j["faults"][0]["start_ns"].get<std::int64_t>(), 500'000'000);
  EXPECT_EQ(j["faults"][1]["kind"], "lidar-dropout");
  const CliResult info = runDrover("info " + out.string() + " --format sim --json " + (dir / "info.json").string());
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const Json k = readJson(dir / "info.json");
  EXPECT_EQ(k["lidar"]["count"].get<int>(), 30 - 3);  // sweeps starting at 2.0, 2.1 and 2.2 s
  EXPECT_EQ(k["imu"]["count"].get<int>(), 601 - 100);
  for (const char* bad : {"camera-off@1+1", "imu-gap@1", "imu-gap@x+1", "imu-gap@1+0", "imu-gap@1+-2", "imu-gap@99+1"}) {
    const CliResult e = runDrover(std::string("sim -q --scenario straight --duration 3 --no-camera --fault ") + bad +
                                  " --out " + (dir / "bad").string());
    EXPECT_EQ(e.exit_code, 2) << bad << ": " << e.output;
    EXPECT_NE(e.output.find("--fault"), std::string::npos) << bad << ": " << e.output;
    EXPECT_FALSE(fs::exists(dir / "bad")) << bad;
  }
}

TEST(SimCli, UnknownScenarioExitsWithCode2AndOneLine) {
  TempDir dir;
  const CliResult r = runDrover("sim --scenario moonbase --out " + (dir / "x").string());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "unknown scenario 'moonbase'")) << r.output;
  EXPECT_TRUE(contains(r.output, "farm")) << "lists the known scenarios: " << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  EXPECT_FALSE(fs::exists(dir / "x"));
}

TEST(SimCli, ExistingOutputFolderNeedsForce) {
  TempDir dir;
  fs::create_directories(dir / "taken");
  const std::string args = "sim --scenario straight --duration 1 --no-camera --out " + (dir / "taken").string();
  const CliResult r = runDrover(args);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.output, "already exists")) << r.output;
  EXPECT_TRUE(contains(r.output, "--force")) << r.output;
  const CliResult forced = runDrover(args + " --force -q");
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  EXPECT_TRUE(fs::exists(dir / "taken" / "calibration.yaml"));
}

TEST(SimCli, TheEurocFormatRefusesALidarAndReplacesOnlyItsOwnOutput) {
  TempDir dir;
  const CliResult lidar =
      runDrover("sim --scenario mav-room --format euroc --lidar vlp16 --duration 1 --out " + (dir / "x").string());
  EXPECT_EQ(lidar.exit_code, 2) << lidar.output;
  EXPECT_TRUE(contains(lidar.output, "--lidar") && contains(lidar.output, "no lidar")) << lidar.output;
  EXPECT_EQ(std::count(lidar.output.begin(), lidar.output.end(), '\n'), 1) << lidar.output;
  EXPECT_FALSE(fs::exists(dir / "x"));
  writeText(dir / "mine" / "notes.txt", "keep\n");
  const CliResult foreign =
      runDrover("sim --scenario mav-room --format euroc --duration 1 --force --out " + (dir / "mine").string());
  EXPECT_EQ(foreign.exit_code, 2) << foreign.output;
  EXPECT_TRUE(contains(foreign.output, "not a simulated EuRoC dataset")) << foreign.output;
  EXPECT_TRUE(fs::exists(dir / "mine" / "notes.txt"));
}

TEST(SimCli, BadArgumentsExitWithCode2) {
  TempDir dir;
  const std::string out = " --out " + (dir / "x").string();
  EXPECT_EQ(runDrover("sim --scenario straight --duration -1" + out).exit_code, 2);
  EXPECT_EQ(runDrover("sim --scenario straight --lidar vlp8" + out).exit_code, 2);
  EXPECT_EQ(runDrover("sim --scenario straight --format rosbag2" + out).exit_code, 2);
  EXPECT_EQ(runDrover("sim --scenario straight --camera-rate 500 --duration 1" + out).exit_code, 2);
  EXPECT_EQ(runDrover("sim --scenario straight").exit_code, 2);  // --out missing
  EXPECT_FALSE(fs::exists(dir / "x"));
}

TEST(SimCli, ADurationBeyondAnHourIsRefusedAtOnceWithTheValidRange) {
  // 1e9 s used to grow the path in memory at 130 MB/s without a word; 1e12 s overflowed into "too short".
  TempDir dir;
  for (const char* d : {"1e9", "1e12", "3600.5"}) {
    const auto t0 = std::chrono::steady_clock::now();
    const CliResult r = runDrover(std::string("sim --scenario farm --no-camera --duration ") + d + " --out " +
                                  (dir / "farm").string());
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "[error] --duration:")) << r.output;
    EXPECT_TRUE(contains(r.output, "(expected [0, 3600] s)")) << r.output;
    EXPECT_LT(wall, 10.0) << d;
  }
  EXPECT_FALSE(fs::exists(dir / "farm"));
  EXPECT_FALSE(fs::exists(dir / "farm.partial"));
}

TEST(SimCli, CameraRateZeroIsAnErrorNotTheDefault) {
  TempDir dir;
  const CliResult r =
      runDrover("sim --scenario straight --duration 1 --camera-rate 0 --out " + (dir / "x").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--camera-rate: 0 Hz is out of range (expected (0, 60] Hz)")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "x"));
}

TEST(SimCli, SeedsOutsideSixtyFourBitsAreErrorsNotTheLargestSeed) {
  TempDir dir;
  for (const char* seed : {"-1", "18446744073709551616", "1180591620717411303424"}) {
    const CliResult r = runDrover(std::string("sim --scenario straight --duration 1 --seed ") + seed + " --out " +
                                  (dir / "x").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_TRUE(contains(r.output, "--seed:")) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir / "x"));
}

}  // namespace
}  // namespace drover::test
