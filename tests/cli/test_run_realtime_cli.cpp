// `drover run --realtime`, end to end: a short simulated course fed at sensor rate through the live system (the run
// takes as long as the data). It writes the replay's files plus report.json's "realtime" section with the names
// scripts rely on, drops nothing on a course this light, and is as accurate as the replay; bad combinations are
// refused before any work.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>
#include <string>

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {
namespace fs = std::filesystem;
using Json = nlohmann::json;

// config/farm_sim.yaml with a sweep queue that holds the whole course: the test suite runs beside this test, and a
// sweep dropped because of it would make the live trajectory differ from the replay's (a queue of 2 drops nothing
// on a quiet machine, bench/RESULTS.md).
std::string deepQueueConfig(const TempDir& dir) {
  std::ifstream in(config("farm_sim.yaml"));
  std::stringstream text;
  text << in.rdbuf() << "\nlive:\n  sweep_queue: 100\n";
  writeText(dir / "platform.yaml", text.str());
  return (dir / "platform.yaml").string();
}

// 6 s of sharp-turns without a camera (2.5 s at rest, then 4 m straight), at three times sensor rate (--rate 3, as
// rosbag play -r 3) and as a replay.
TEST(RunRealtime, WritesTheReplaysFilesWithLatencyPerOutputAndDropsNothingOnALightCourse) {
  TempDir dir;
  const CliResult sim =
      runDrover("sim -q --scenario sharp-turns --duration 6 --no-camera --out " + (dir / "course").string());
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const std::string run =
      "run " + (dir / "course").string() + " --format sim --config " + deepQueueConfig(dir) + " --no-loop";
  const CliResult live = runDrover(run + " --realtime --rate 3 --out " + (dir / "live").string());
  ASSERT_EQ(live.exit_code, 0) << live.output;
  EXPECT_TRUE(contains(live.output, "realtime: latency sweep end -> pose")) << live.output;
  const CliResult replay = runDrover(run + " -q --out " + (dir / "replay").string());
  ASSERT_EQ(replay.exit_code, 0) << replay.output;

  for (const char* f : {"trajectory.tum", "keyframes.tum", "trajectory_imu_rate.tum", "map.pcd", "report.json"})
    EXPECT_TRUE(fs::is_regular_file(dir / "live" / f)) << f;
  const Json r = readJson(dir / "live" / "report.json");
  ASSERT_TRUE(r.contains("realtime")) << r.dump().substr(0, 400);
  const Json& rt = r["realtime"];
  for (const char* k : {"sweep", "imu_rate"})
    for (const char* q : {"p50", "p95", "max"}) EXPECT_TRUE(rt["latency_ms"][k][q].is_number()) << k << " " << q;
  EXPECT_EQ(rt["sweeps_dropped"], 0);
  EXPECT_EQ(rt["sweeps_pushed"], 60);
  // The IMU-rate pose is propagated on the pushing thread: well under a millisecond typically, 2 ms asked.
  EXPECT_LT(rt["latency_ms"]["imu_rate"]["p50"].get<double>(), 2.0);
  EXPECT_GT(rt["latency_ms"]["imu_rate"]["count"].get<int>(), 600);  // 200 Hz once initialised
  // Paced: the run takes as long as the data played three times as fast (the replay takes a fraction of it).
  EXPECT_EQ(rt["rate"].get<double>(), 3.0);
  EXPECT_GT(r["wall_s"].get<double>(), 6.0 / 3 - 0.2);
  EXPECT_LT(r["wall_s"].get<double>(), 4.5);
  const Json p = readJson(dir / "replay" / "report.json");
  EXPECT_FALSE(p.contains("realtime"));
  EXPECT_EQ(r["counts"]["scans_processed"], p["counts"]["scans_processed"]);
  // Nothing dropped and no loop closure: the live LIS saw the replay's measurements in the same order.
  const Trajectory a = io::readTum((dir / "live" / "trajectory.tum").string());
  const Trajectory b = io::readTum((dir / "replay" / "trajectory.tum").string());
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_LT((a[i].T_world_body.translation() - b[i].T_world_body.translation()).norm(), 1e-6) << i;
}

TEST(RunRealtime, ARateWithoutRealtimeIsRefusedBeforeAnyWork) {
  TempDir dir;
  const CliResult r =
      runDrover("run " + dir.path().string() + " --format sim --rate 0.5 --out " + (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--rate sets the speed of the --realtime replay")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(RunRealtime, WithNoLidarItIsRefusedBeforeAnyWork) {
  TempDir dir;
  const CliResult r = runDrover("run " + dir.path().string() + " --format sim --realtime --no-lidar --out " +
                                (dir / "out").string());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "--realtime with --no-lidar")) << r.output;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace drover::test
