// What drover run keeps of its sweeps (apps/drover/run_record.hpp), bounded for hour-long runs: quantiles exact for
// short runs and within their 1 % bins for long ones, the per-sweep lines streamed or the newest kept, the IMU-rate
// odometry streamed in trajectory.tum's body frame; the heap's free pages handed back every 30 s.
#include "apps/drover/run_record.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "apps/drover/heap_tuning.hpp"

#include "io/trajectory_io.hpp"
#include "support/cli.hpp"
#include "support/temp_dir.hpp"

namespace drover::cli {
namespace {

TEST(BoundedQuantiles, AreExactForAShortStream) {
  BoundedQuantiles q;
  EXPECT_TRUE(q.percentiles()["p95"].is_null());
  for (int v = 100; v >= 1; --v) q.add(v);  // 1..100, in any order
  EXPECT_EQ(q.count(), 100u);
  EXPECT_DOUBLE_EQ(q.quantile(0.5), 51.0);   // rank round(0.5 * 99) = 50 (0-based)
  EXPECT_DOUBLE_EQ(q.quantile(0.95), 95.0);  // rank round(0.95 * 99) = 94
  EXPECT_DOUBLE_EQ(q.max(), 100.0);
  EXPECT_DOUBLE_EQ(q.mean(), 50.5);
}

TEST(BoundedQuantiles, StayWithinOnePercentAndKeepExactMeanAndMaxForAnHourAtTwoHundredHertz) {
  BoundedQuantiles q;
  const std::size_t n = 720'000;  // an hour of IMU-rate latencies
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = 0.01 + 10.0 * static_cast<double>((i * 7919) % n) / static_cast<double>(n);  // uniform [0.01, 10.01)
    q.add(v);
    sum += v;
  }
  EXPECT_NEAR(q.quantile(0.5), 5.01, 0.01 * 5.01);
  EXPECT_NEAR(q.quantile(0.95), 9.51, 0.01 * 9.51);
  EXPECT_NEAR(q.mean(), sum / static_cast<double>(n), 1e-9);
  EXPECT_NEAR(q.max(), 0.01 + 10.0 * static_cast<double>(n - 1) / static_cast<double>(n), 1e-12);
  EXPECT_LE(q.quantile(1.0), q.max());
}

pipeline::ScanOutcome sweepAt(double t_s, bool imu) {
  pipeline::ScanOutcome s;
  s.t = fromSeconds(t_s);
  s.match_status = "converged";
  s.ms.total = 10 * t_s;
  s.has_imu_state = imu;
  return s;
}

TEST(SweepLog, StreamsEveryLineToItsFileOrKeepsOnlyTheNewest) {
  const test::TempDir dir;
  RunRecord streamed;
  streamed.log.streamTo((dir / "all.jsonl").string());
  RunRecord kept;
  kept.log.keepNewest(3);
  for (int k = 1; k <= 10; ++k) {
    streamed.add(sweepAt(k, true));
    kept.add(sweepAt(k, false));
  }
  streamed.log.finish((dir / "unused.jsonl").string());
  kept.log.finish((dir / "newest.jsonl").string());
  const nlohmann::json all = test::readJsonLines(dir / "all.jsonl");
  ASSERT_EQ(all.size(), 10u);
  EXPECT_DOUBLE_EQ(all[9]["t"].get<double>(), 10.0);
  EXPECT_TRUE(all[0].contains("gyro_bias"));
  const nlohmann::json newest = test::readJsonLines(dir / "newest.jsonl");
  ASSERT_EQ(newest.size(), 3u);
  EXPECT_DOUBLE_EQ(newest[0]["t"].get<double>(), 8.0);
  EXPECT_FALSE(newest[0].contains("gyro_bias"));
  EXPECT_EQ(kept.sweeps, 10u);
  EXPECT_EQ(kept.first_t, fromSeconds(1.0));
  EXPECT_EQ(kept.last_t, fromSeconds(10.0));
  EXPECT_DOUBLE_EQ(kept.stage_ms[7].max(), 100.0);  // "total"
  EXPECT_STREQ(RunRecord::stageNames()[7], "total");
}

// A degenerate sweep says which directions the lidar left to the IMU and how weakly it held the weakest (the number
// matcher.degeneracy_threshold is compared with), and a sweep with a problem carries its warning (a smoother
// restart's reason); a healthy sweep carries neither.
TEST(SweepLog, ALineNamesTheDegenerateDirectionsTheSmallestEigenvalueAndTheWarning) {
  const test::TempDir dir;
  RunRecord record;
  record.log.streamTo((dir / "sweeps.jsonl").string());
  pipeline::ScanOutcome degenerate = sweepAt(1, true);
  degenerate.degenerate = true;
  degenerate.degenerate_count = 1;
  degenerate.degenerate_directions = {(Eigen::Matrix<double, 6, 1>() << 0.99995, 0.01, 0, 0, 0, 0.0001).finished()};
  degenerate.min_eigenvalue = 22.37;
  degenerate.warning = "IMU does not cover the sweep: smoother restarted at the lidar pose";
  record.add(degenerate);
  pipeline::ScanOutcome healthy = sweepAt(2, true);
  healthy.min_eigenvalue = 512.0;
  record.add(healthy);
  record.log.finish((dir / "unused.jsonl").string());
  const nlohmann::json lines = test::readJsonLines(dir / "sweeps.jsonl");
  ASSERT_EQ(lines.size(), 2u);
  ASSERT_EQ(lines[0]["degenerate_directions"].size(), 1u);
  const std::vector<double> d = lines[0]["degenerate_directions"][0].get<std::vector<double>>();
  ASSERT_EQ(d.size(), 6u);
  EXPECT_DOUBLE_EQ(d[0], 1.0) << "a direction is written to 4 decimals";
  EXPECT_DOUBLE_EQ(d[1], 0.01);
  EXPECT_DOUBLE_EQ(d[5], 0.0001);
  EXPECT_DOUBLE_EQ(lines[0]["min_eigenvalue"].get<double>(), 22.4);
  EXPECT_EQ(lines[0]["warning"], degenerate.warning);
  EXPECT_FALSE(lines[1].contains("degenerate_directions"));
  EXPECT_FALSE(lines[1].contains("warning"));
  EXPECT_DOUBLE_EQ(lines[1]["min_eigenvalue"].get<double>(), 512.0);
}

TEST(ImuRateFile, StreamsPosesInTheBodyFrameSkipsRepeatsAndCopiesWhatItHasSoFar) {
  const test::TempDir dir;
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  T_imu_lidar.translation() = Eigen::Vector3d(0.05, 0, 0.3);
  ImuRateFile file((dir / "imu_rate.tum").string(), T_imu_lidar);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int k = 0; k < 5; ++k) {
    T.translation().x() = k;
    file.add(fromSeconds(k * 0.005), T);
  }
  file.add(fromSeconds(0.01), T);  // a repeat: skipped
  const ImuRateFile::Summary s = file.copyTo((dir / "copy.tum").string());
  EXPECT_EQ(s.poses, 5u);
  EXPECT_EQ(s.first, 0);
  EXPECT_EQ(s.last, fromSeconds(0.02));
  const Trajectory copy = io::readTum((dir / "copy.tum").string());
  ASSERT_EQ(copy.size(), 5u);
  EXPECT_NEAR((copy[4].T_world_body.translation() - Eigen::Vector3d(4.05, 0, 0.3)).norm(), 0, 1e-9);
  EXPECT_EQ(file.copyTo((dir / "imu_rate.tum").string()).poses, 5u);  // onto itself: only flushed
  EXPECT_EQ(io::readTum((dir / "imu_rate.tum").string()).size(), 5u);
}

long residentKb() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

// With drover's heap settings nothing freed goes back to the kernel by itself; the trimmer returns it once per
// period of data time. A sweep stamped at its start comes after the IMU samples of its revolution: such small steps
// back must neither trim every sweep nor hold the trim off for ever; a jump back by more than a period restarts it.
TEST(HeapTrimmer, HandsTheHeapsFreePagesBackOncePerPeriodOfDataTime) {
  tuneHeapForSweeps();
  HeapTrimmer trimmer(30'000'000'000);
  EXPECT_FALSE(trimmer.tick(5'000'000'000)) << "the first tick starts the clock";
  constexpr std::size_t kBlock = 1 << 20, kBlocks = 64;  // [bytes] below the 32 MiB mmap threshold: in the heap
  std::vector<char*> blocks;
  volatile char sink = 0;
  for (std::size_t i = 0; i < kBlocks; ++i) {
    blocks.push_back(static_cast<char*>(std::malloc(kBlock)));
    std::memset(blocks.back(), 1, kBlock);
    sink = sink + blocks.back()[kBlock / 2];
  }
  char* pin = static_cast<char*>(std::malloc(64));  // keeps the freed blocks inside the heap, not at its top
  pin[0] = 1;
  const long held = residentKb();
  for (char* b : blocks) std::free(b);
  EXPECT_FALSE(trimmer.tick(34'999'999'999));
  EXPECT_GT(residentKb(), held - 8 * 1024) << "freed blocks stay resident between trims";
  EXPECT_TRUE(trimmer.tick(35'000'000'000));
  EXPECT_LT(residentKb(), held - 32 * 1024) << "the trim returns the 64 MiB freed inside the heap";
  EXPECT_FALSE(trimmer.tick(64'000'000'000));
  EXPECT_TRUE(trimmer.tick(65'000'000'000));
  EXPECT_FALSE(trimmer.tick(64'900'000'000)) << "a small step back neither trims nor restarts the period";
  EXPECT_FALSE(trimmer.tick(94'900'000'000));
  EXPECT_TRUE(trimmer.tick(95'000'000'000));
  EXPECT_FALSE(trimmer.tick(10'000'000'000)) << "a jump back by more than a period restarts it";
  EXPECT_FALSE(trimmer.tick(39'900'000'000));
  EXPECT_TRUE(trimmer.tick(40'000'000'000));
  EXPECT_EQ(trimmer.trims(), 4);
  std::free(pin);
}

}  // namespace
}  // namespace drover::cli
