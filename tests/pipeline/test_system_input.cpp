// Bad live input to pipeline::System on a simulated course with exact ground truth: sweeps out of order, a sensor
// that stops and restarts, a clock that jumps back, a burst of messages. Each gives warnings and counts, never a
// crash or a hang (shutdown() returns), and where the data allow it the LIS keeps tracking the truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "pipeline/system.hpp"
#include "support/live_course.hpp"

namespace drover::pipeline {
namespace {

// 16 s of the sharp-turns course (at rest 2.5 s, 11 m straight, then turning), VLP-16 at 10 Hz and IMU at 200 Hz.
const test::LiveCourse& inputCourse() {
  static const test::LiveCourse c = test::simulateLiveCourse("sharp-turns", 16.0, 7);
  return c;
}

Time stampOf(const Measurement& m) {
  if (const auto* imu = std::get_if<ImuSample>(&m)) return imu->t;
  if (const auto* scan = std::get_if<LidarScan>(&m)) return scan->t;
  return std::get<CameraFrame>(m).t;
}

// Collects the warnings and counts the sweeps the LIS processed.
struct Listener {
  std::mutex mutex;
  std::vector<std::string> warnings;
  std::atomic<std::size_t> sweeps{0};
  std::atomic<std::size_t> jumps{0};
  std::string jumped_stream;

  SystemCallbacks callbacks() {
    SystemCallbacks cb;
    cb.sweep = [this](const ScanOutcome&) { ++sweeps; };
    cb.warning = [this](const std::string& w) {
      std::lock_guard<std::mutex> lock(mutex);
      warnings.push_back(w);
    };
    cb.clock_jump = [this](const std::string& stream, Time, Time) {
      std::lock_guard<std::mutex> lock(mutex);
      jumped_stream = stream;
      ++jumps;
    };
    return cb;
  }
  std::size_t count(const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex);
    return static_cast<std::size_t>(std::count_if(warnings.begin(), warnings.end(), [&](const std::string& w) {
      return w.find(text) != std::string::npos;
    }));
  }
};

SystemConfig inputConfig(int sweep_queue) {
  SystemConfig c;
  c.odometry = test::simOdometryConfig();
  c.live.sweep_queue = sweep_queue;
  return c;
}

std::size_t sweepsIn(const std::vector<Measurement>& stream) {
  return static_cast<std::size_t>(std::count_if(stream.begin(), stream.end(), [](const Measurement& m) {
    return std::holds_alternative<LidarScan>(m);
  }));
}

// Every 20th sweep from the 20th on comes after the sweep that follows it (7 pairs swapped): the late one is
// skipped as the LIS skips a backwards stamp, with its notice as a live warning, and the rest track the truth.
TEST(SystemInput, SweepsOutOfOrderAreSkippedWithAWarningAndTheOthersTrackTheTruth) {
  std::vector<Measurement> stream = inputCourse().stream;
  std::vector<std::size_t> sweeps;
  for (std::size_t i = 0; i < stream.size(); ++i)
    if (std::holds_alternative<LidarScan>(stream[i])) sweeps.push_back(i);
  std::size_t swapped = 0;
  for (std::size_t k = 20; k + 1 < sweeps.size(); k += 20, ++swapped) std::swap(stream[sweeps[k]], stream[sweeps[k + 1]]);
  ASSERT_EQ(swapped, 7u);
  Listener l;
  System system(inputConfig(1'000'000), inputCourse().calibration, l.callbacks());
  for (const Measurement& m : stream) test::pushMeasurement(system, m);
  system.shutdown();
  EXPECT_EQ(system.lis().stats().scans_skipped_time, swapped);
  EXPECT_EQ(l.count("is not after the previous sweep's"), swapped);
  EXPECT_EQ(l.sweeps.load(), sweeps.size() - swapped);
  EXPECT_EQ(system.stats().clock_jumps, 0u);  // 0.1 s back is out of order, not a clock jump
  const double worst = test::worstSweepError(system.lis().trajectory(), inputCourse());
  std::printf("7 sweeps out of order: worst sweep position error %.3f m\n", worst);
  EXPECT_LT(worst, 0.10);  // [m] as without the swaps
}

// The lidar is silent from 6 s to 9 s while the robot drives (3 s, ~3 m): the IMU carries the LIS across, the
// restart is reported, and the LIS tracks on. Then the IMU is silent from 11 s to 11.6 s: the LIS reports the gap
// and carries on.
TEST(SystemInput, ASensorThatStopsAndRestartsIsReportedAndTheLisTracksOn) {
  std::vector<Measurement> stream;
  for (const Measurement& m : inputCourse().stream) {
    const double t = toSeconds(stampOf(m));
    if (std::holds_alternative<LidarScan>(m) && t > 6.0 && t < 9.0) continue;
    if (std::holds_alternative<ImuSample>(m) && t > 11.0 && t < 11.6) continue;
    stream.push_back(m);
  }
  Listener l;
  System system(inputConfig(1'000'000), inputCourse().calibration, l.callbacks());
  test::feedAsInRealTime(system, stream, l.sweeps);
  system.shutdown();
  EXPECT_EQ(system.stats().sensor_restarts, 1u);
  EXPECT_EQ(l.count("the lidar was silent for 3.0"), 1u);
  EXPECT_EQ(l.count("LIS: IMU gap of 0.600 s"), 1u);  // in the LIS's words
  EXPECT_EQ(system.lis().stats().imu.gaps, 1u);
  EXPECT_EQ(l.sweeps.load(), sweepsIn(stream));
  EXPECT_EQ(system.stats().sweeps_dropped, 0u);
  const double worst = test::worstSweepError(system.lis().trajectory(), inputCourse());
  std::printf("lidar silent 3 s, IMU silent 0.6 s: worst sweep position error %.3f m\n", worst);
  EXPECT_LT(worst, 0.15);  // [m]
}

// At 8 s every sensor's clock jumps back 5 s (a recording restarted, a clock reset): reported once, through the
// callback and a warning; everything after it is ignored and counted (it cannot be told from a robot that moved);
// what came before is processed, and shutdown returns.
TEST(SystemInput, AClockThatJumpsBackStopsTheInputWithOneReportAndShutsDownCleanly) {
  std::vector<Measurement> before, after;
  const Time jump_at = fromSeconds(8.0), back = fromSeconds(5.0);
  for (Measurement m : inputCourse().stream) {
    if (stampOf(m) < jump_at) {
      before.push_back(std::move(m));
      continue;
    }
    if (auto* imu = std::get_if<ImuSample>(&m)) imu->t -= back;
    if (auto* scan = std::get_if<LidarScan>(&m)) {
      scan->t -= back;
      scan->t_end -= back;
    }
    after.push_back(std::move(m));
  }
  Listener l;
  System system(inputConfig(1'000'000), inputCourse().calibration, l.callbacks());
  test::feedAsInRealTime(system, before, l.sweeps);
  for (const Measurement& m : after) test::pushMeasurement(system, m);  // all ignored: no pacing needed
  system.shutdown();
  const SystemStats s = system.stats();
  EXPECT_EQ(l.jumps.load(), 1u);
  EXPECT_EQ(l.jumped_stream, "imu");  // the IMU's sample at 8 s is the first measurement after the jump
  EXPECT_EQ(s.clock_jumps, 1u);
  EXPECT_EQ(l.count("clock jumped back 4.995 s"), 1u);  // from the sample at 7.995 s to 3.000 s
  EXPECT_EQ(s.ignored_after_jump, after.size());
  EXPECT_EQ(s.imu_pushed + s.sweeps_pushed, before.size() + after.size());
  // The sweeps before the jump were processed (the last waits for IMU data that never came: processed at shutdown).
  const Trajectory& t = system.lis().trajectory();
  ASSERT_FALSE(t.empty());
  EXPECT_LT(t.back().t, jump_at);
  EXPECT_GE(t.back().t, jump_at - fromSeconds(0.3));
  EXPECT_LT(test::worstSweepError(t, inputCourse()), 0.10);
}

// After 5 s, 3 s of data (30 sweeps, 600 IMU samples) arrive at once, as from a stalled network link, with the
// default queue of 2 sweeps: the oldest waiting sweeps are dropped with counted warnings, every IMU sample is kept,
// and the LIS, fed at sensor rate again, tracks on to the end.
TEST(SystemInput, ABurstOfMessagesDropsTheOldestWaitingSweepsAndTheLisRecovers) {
  const Time burst_from = fromSeconds(5.0), burst_to = fromSeconds(8.0);
  std::vector<Measurement> head, burst, tail;
  for (const Measurement& m : inputCourse().stream) {
    const Time t = stampOf(m);
    (t < burst_from ? head : t < burst_to ? burst : tail).push_back(m);
  }
  Listener l;
  System system(inputConfig(2), inputCourse().calibration, l.callbacks());
  test::feedAsInRealTime(system, head, l.sweeps);
  for (const Measurement& m : burst) test::pushMeasurement(system, m);
  test::feedAsInRealTime(system, tail, l.sweeps);
  system.shutdown();
  const SystemStats s = system.stats();
  const std::size_t burst_sweeps = sweepsIn(burst);
  ASSERT_EQ(burst_sweeps, 30u);
  EXPECT_GE(s.sweeps_dropped, burst_sweeps - 8);  // a queue of 2, and the LIS takes a few while they come in
  EXPECT_LE(s.sweeps_dropped, burst_sweeps);
  EXPECT_EQ(l.sweeps.load() + s.sweeps_dropped, s.sweeps_pushed);
  EXPECT_EQ(l.count("sweep dropped"), std::min<std::size_t>(s.sweeps_dropped, 10));
  EXPECT_EQ(system.lis().stats().imu.accepted, s.imu_pushed);
  EXPECT_EQ(system.lis().stats().imu.dropped_out_of_order, 0u);
  // ~3 m driven on the IMU across the dropped sweeps, then matched again: within a few cm of the truth at the end.
  const double worst = test::worstSweepError(system.lis().trajectory(), inputCourse(), burst_to);
  std::printf("burst: %zu of %zu sweeps dropped; worst sweep position error after it %.3f m\n", s.sweeps_dropped,
              burst_sweeps, worst);
  EXPECT_LT(worst, 0.15);
}

TEST(SystemInput, RejectsANonPositiveClockJumpOrSensorGapNamingTheKey) {
  SystemConfig c = inputConfig(2);
  c.live.clock_jump_s = 0;
  EXPECT_EQ(c.live.validate(), "live.clock_jump_s must be > 0");
  c.live.clock_jump_s = 1;
  c.live.sensor_gap_s = -1;
  EXPECT_EQ(c.live.validate(), "live.sensor_gap_s must be > 0");
  EXPECT_THROW(System(c, inputCourse().calibration, {}), std::invalid_argument);
}

}  // namespace
}  // namespace drover::pipeline
