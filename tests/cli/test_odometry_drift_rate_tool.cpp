// tools/odometry_drift_rate.py, which gives the loop graph's odometry sigmas of a platform file (config/car_sim.yaml):
// on a straight course whose estimate runs 1 % long and turns 1e-3 rad more each keyframe, the error over a span of N
// keyframes is 0.01 N m / 1e-3 N rad, and the random-walk sigma per step it reports is that over sqrt(N).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover {
namespace {

std::string tumYawLine(double t_s, double x, double yaw) {
  char line[200];
  std::snprintf(line, sizeof line, "%.9f %.9f 0 0 0 0 %.12f %.12f\n", t_s, x, std::sin(yaw / 2), std::cos(yaw / 2));
  return line;
}

nlohmann::json runTool(const test::TempDir& dir, const std::string& estimate) {
  std::string truth;
  for (int k = 0; k < 40; ++k) truth += tumYawLine(k, k, 0);  // 1 m a keyframe along x, one keyframe a second
  test::writeText(dir / "course" / "groundtruth.txt", truth);
  test::writeText(dir / "run" / "keyframes.tum", estimate);
  const test::CliResult r = test::runShell("/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) +
                                          "/tools/odometry_drift_rate.py " + (dir / "course").string() + " " +
                                          (dir / "run").string() + " --spans 1 4 16 --json " +
                                          (dir / "rate.json").string() + " 2>&1");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return test::readJson(dir / "rate.json");
}

TEST(OdometryDriftRateTool, GivesTheRandomWalkSigmaPerStepOfAScaleError) {
  test::TempDir dir;
  std::string estimate;
  for (int k = 0; k < 40; ++k) estimate += tumYawLine(k, 1.01 * k, 0);
  const nlohmann::json j = runTool(dir, estimate);
  ASSERT_EQ(j.at("spans").size(), 3u);
  for (const auto& span : j.at("spans")) {
    const double n = span.at("keyframes").get<double>();
    EXPECT_NEAR(span.at("length_m").get<double>(), n, 1e-9);
    EXPECT_NEAR(span.at("translation_rms_m").get<double>(), 0.01 * n, 1e-9);
    EXPECT_NEAR(span.at("sigma_position_m").get<double>(), 0.01 * std::sqrt(n), 1e-9);
    EXPECT_NEAR(span.at("sigma_rotation_rad").get<double>(), 0.0, 1e-7);
  }
}

TEST(OdometryDriftRateTool, GivesTheRandomWalkSigmaPerStepOfAHeadingRateError) {
  test::TempDir dir;
  std::string estimate;
  for (int k = 0; k < 40; ++k) estimate += tumYawLine(k, k, 1e-3 * k);
  const nlohmann::json j = runTool(dir, estimate);
  ASSERT_EQ(j.at("spans").size(), 3u);
  for (const auto& span : j.at("spans")) {
    const double n = span.at("keyframes").get<double>();
    EXPECT_NEAR(span.at("rotation_rms_rad").get<double>(), 1e-3 * n, 1e-8);
    EXPECT_NEAR(span.at("sigma_rotation_rad").get<double>(), 1e-3 * std::sqrt(n), 1e-8);
  }
}

TEST(OdometryDriftRateTool, NamesTheMissingFileAndFails) {
  test::TempDir dir;
  const test::CliResult r = test::runShell("/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) +
                                          "/tools/odometry_drift_rate.py " + (dir / "nope").string() + " " +
                                          dir.path().string() + " 2>&1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("groundtruth.txt: no such file"), std::string::npos) << r.output;
}

TEST(OdometryDriftRateTool, NamesAFileThatIsNotATrajectoryAndFails) {
  test::TempDir dir;
  test::writeText(dir / "course" / "groundtruth.txt", tumYawLine(0, 0, 0) + tumYawLine(1, 1, 0));
  test::writeText(dir / "run" / "keyframes.tum", "0 1 2\n");
  const test::CliResult r = test::runShell("/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) +
                                          "/tools/odometry_drift_rate.py " + (dir / "course").string() + " " +
                                          (dir / "run").string() + " 2>&1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("keyframes.tum: not a TUM trajectory"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Traceback"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace drover
