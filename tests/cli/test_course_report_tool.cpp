// tools/course_report.py, which the ablation table and the README's course figures read: on a straight course
// whose estimate steps 0.1 m sideways half way, the first-pose-aligned errors are 0 then 0.1 m, and their
// statistics (max, min, std, median, mean, rmse) and the drift are those numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover {
namespace {

std::string tumLine(double t_s, double x, double y) {
  char line[160];
  std::snprintf(line, sizeof line, "%.9f %.6f %.6f 0 0 0 0 1\n", t_s, x, y);
  return line;
}

TEST(CourseReportTool, GivesTheFirstPoseAlignedErrorStatisticsOfAStraightCourse) {
  test::TempDir dir;
  const auto data = dir / "course";
  const auto run = dir / "run";
  std::string truth, estimate;
  for (int k = 0; k < 10; ++k) {  // 1 m a step along x; the estimate 0.1 m off in y from the sixth pose on
    truth += tumLine(k, k, 0);
    estimate += tumLine(k, k, k >= 5 ? 0.1 : 0.0);
  }
  test::writeText(data / "groundtruth.txt", truth);
  test::writeText(data / "scenario.json", R"({"scenario": "straight", "segments": []})");
  test::writeText(run / "trajectory.tum", estimate);
  const test::CliResult r = test::runShell("/usr/bin/python3 " + std::string(DROVER_SOURCE_DIR) +
                                          "/tools/course_report.py " + data.string() + " " + run.string() +
                                          " --json " + (dir / "report.json").string() + " 2>&1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = test::readJson(dir / "report.json");
  const nlohmann::json& ape = j.at("ape_first_pose_aligned_m");
  EXPECT_NEAR(ape.at("max").get<double>(), 0.1, 1e-6);
  EXPECT_NEAR(ape.at("min").get<double>(), 0.0, 1e-6);
  EXPECT_NEAR(ape.at("median").get<double>(), 0.05, 1e-6);
  EXPECT_NEAR(ape.at("mean").get<double>(), 0.05, 1e-6);
  EXPECT_NEAR(ape.at("std").get<double>(), 0.05, 1e-6);
  EXPECT_NEAR(ape.at("rmse").get<double>(), std::sqrt(0.5 * 0.01), 1e-6);
  EXPECT_NEAR(j.at("end_error_m").get<double>(), 0.1, 1e-6);
  EXPECT_NEAR(j.at("drift_percent").get<double>(), 100 * 0.1 / 9.0, 1e-4);
}

}  // namespace
}  // namespace drover
