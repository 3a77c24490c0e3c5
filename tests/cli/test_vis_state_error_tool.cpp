// tools/vis_state_error.py, which measures what a VIS dead-reckons with where it sees no motion: on a level drive at
// 1 m/s whose VIS pitches its body by delta and holds an accelerometer bias b, the body-frame acceleration it makes
// of the specific force is off the truth by (b_true - b) - g (R_vis^T z - z); forward b_true,x - b_x + g sin(delta).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover {
namespace {

// A TUM line at t [s], x [m], pitched by `pitch` [rad] about the body's y axis.
std::string pitchedPoseLine(double t_s, double x, double pitch) {
  char line[200];
  std::snprintf(line, sizeof line, "%.9f %.9f 0 0.4 0 %.12f 0 %.12f\n", t_s, x, std::sin(pitch / 2),
                std::cos(pitch / 2));
  return line;
}

test::CliResult runStateErrorTool(const test::TempDir& dir, const std::string& extra) {
  return test::runShell("/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) + "/tools/vis_state_error.py " +
                        (dir / "course").string() + " " + (dir / "run").string() + " " + extra + " 2>&1");
}

TEST(VisStateErrorTool, GivesTheForwardErrorOfABiasAndAPitchTheVisGotWrong) {
  test::TempDir dir;
  constexpr double kPitch = 0.002, kBias = 0.005, kSpeed = 1.03;  // [rad], [m/s^2], [m/s]
  std::string truth, vis, frames;
  for (int k = 0; k <= 2000; ++k) truth += pitchedPoseLine(k * 0.005, k * 0.005, 0);  // 1 m/s, 200 Hz, 10 s
  for (int k = 1; k < 10; ++k) {
    vis += pitchedPoseLine(k, 1.0 * k, kPitch);
    frames += "{\"t\":" + std::to_string(k) + ",\"initialized\":true,\"speed\":" + std::to_string(kSpeed) +
              ",\"acc_bias\":[" + std::to_string(kBias) + ",0,0.01],\"on_ground\":40,\"keyframe\":true}\n";
  }
  frames += "{\"t\":0.5,\"initialized\":false}\n";  // not yet initialised: no state, skipped
  test::writeText(dir / "course" / "groundtruth.txt", "# t x y z qx qy qz qw\n" + truth);
  test::writeText(dir / "run" / "trajectory_vis.tum", vis);
  test::writeText(dir / "run" / "vis_frames.jsonl", frames);
  const test::CliResult r = runStateErrorTool(dir, "--at 2 5 --acc-bias 0.02 -0.03 0.01 --json " +
                                                       (dir / "rows.json").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = test::readJson(dir / "rows.json");
  ASSERT_EQ(j.at("rows").size(), 2u);
  for (const auto& row : j.at("rows")) {
    EXPECT_NEAR(row.at("speed_error").get<double>(), kSpeed - 1.0, 1e-6);
    // R_vis = Ry(delta): R_vis^T z = (-sin delta, 0, cos delta), so gravity leaks +g sin(delta) forward.
    EXPECT_NEAR(row.at("forward_from_tilt").get<double>(), 9.81 * std::sin(kPitch), 1e-9);
    EXPECT_NEAR(row.at("forward").get<double>(), 0.02 - kBias + 9.81 * std::sin(kPitch), 1e-9);
    EXPECT_NEAR(row.at("lateral").get<double>(), -0.03, 1e-9);
    EXPECT_NEAR(row.at("up").get<double>(), 0.0 - 9.81 * (std::cos(kPitch) - 1), 1e-9);
  }
}

TEST(VisStateErrorTool, NamesTheMissingFileOrTheBadLineAndFails) {
  test::TempDir dir;
  test::writeText(dir / "course" / "groundtruth.txt", pitchedPoseLine(0, 0, 0) + pitchedPoseLine(1, 1, 0));
  test::writeText(dir / "run" / "trajectory_vis.tum", pitchedPoseLine(0, 0, 0));
  test::CliResult r = runStateErrorTool(dir, "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("vis_frames.jsonl: no such file"), std::string::npos) << r.output;
  test::writeText(dir / "run" / "vis_frames.jsonl", "{\"t\":0}\n{broken\n");
  r = runStateErrorTool(dir, "");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("vis_frames.jsonl: line 2: not JSON"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace drover
