// The `live:` section of a platform config (the live system: drover run --realtime, the ROS node): every key reaches
// LiveConfig, an unknown key or a bad value is an error naming the file, the line and the key, and without the
// section the defaults hold. (In tests/cli because that test module links drover_io_odometry.)
#include <gtest/gtest.h>

#include <string>

#include "io/odometry/live_config_io.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"

namespace drover::test {
namespace {

TEST(LiveConfigIo, KeysReachTheConfigAndAMissingSectionKeepsTheDefaults) {
  TempDir dir;
  const pipeline::LiveConfig c =
      io::loadLiveConfig(writePlatformFile(dir, "live:\n  sweep_queue: 4\n  frame_queue: 3\n  loop_rate_hz: 2.5\n"
                                    "  clock_jump_s: 0.5\n  sensor_gap_s: 2\n"));
  EXPECT_EQ(c.sweep_queue, 4);
  EXPECT_DOUBLE_EQ(c.clock_jump_s, 0.5);
  EXPECT_DOUBLE_EQ(c.sensor_gap_s, 2.0);
  EXPECT_EQ(c.frame_queue, 3);
  EXPECT_DOUBLE_EQ(c.loop_rate_hz, 2.5);
  const pipeline::LiveConfig d = io::loadLiveConfig(writePlatformFile(dir, "odometry:\n  use_imu: true\n"));
  EXPECT_EQ(d.sweep_queue, pipeline::LiveConfig{}.sweep_queue);
}

TEST(LiveConfigIo, AnUnknownKeyOrABadValueNamesTheFileTheLineAndTheKey) {
  TempDir dir;
  const std::string bad_queue = writePlatformFile(dir, "live:\n  sweep_queue: 0\n");
  expectIoError([&] { io::loadLiveConfig(bad_queue); }, {bad_queue, "live.sweep_queue"});
  const std::string unknown = writePlatformFile(dir, "live:\n  sweep_queues: 2\n");
  expectIoError([&] { io::loadLiveConfig(unknown); }, {unknown, "line 2", "sweep_queues"});
  const std::string junk = writePlatformFile(dir, "live:\n  loop_rate_hz: fast\n");
  expectIoError([&] { io::loadLiveConfig(junk); }, {junk, "loop_rate_hz"});
  const std::string no_jump = writePlatformFile(dir, "live:\n  clock_jump_s: 0\n");
  expectIoError([&] { io::loadLiveConfig(no_jump); }, {no_jump, "live.clock_jump_s"});
}

}  // namespace
}  // namespace drover::test
