// Scan layout: per-point time and ring inference against the simulator's exact values and a real KITTI scan, and
// sanitising of invalid returns.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "io/kitti_common.hpp"
#include "lidar/scan_layout.hpp"
#include "sim/lidar_model.hpp"
#include "support/shared_data.hpp"
#include "support/units.hpp"

namespace drover::lidar {
namespace {

using ::drover::test::kSec;
using ::drover::test::kDeg;

sim::SplineTrajectory standingStill(const Eigen::Vector3d& p, double yaw) {
  std::vector<sim::PathSample> samples;
  for (int k = 0; k <= 10; ++k) {
    sim::PathSample s;
    s.t = k * kSec / 10;
    s.p_world = p;
    s.yaw = yaw;
    samples.push_back(s);
  }
  return sim::SplineTrajectory(samples);
}

// A closed 20 x 14 x 10 m room: every beam hits something.
sim::World layoutRoom() {
  sim::World w;
  sim::Box box;
  box.half_extents = Eigen::Vector3d(10, 7, 5);
  w.addBox(box, sim::Material{});
  w.build();
  return w;
}

LidarScan simulatedVlp16(bool clockwise = false) {
  sim::LidarModelConfig c = sim::LidarModelConfig::forModel("vlp16");
  c.noise = false;
  c.spin_clockwise = clockwise;
  return sim::simulateSweep(layoutRoom(), standingStill({1.0, -2.0, 0.3}, 0.4), Eigen::Isometry3d::Identity(), kSec / 5,
                            c, 1, 0);
}

double elevationOf(const LidarPoint& p) { return std::atan2(double(p.z), std::hypot(double(p.x), double(p.y))); }

void checkTimesWithinOneColumn(bool clockwise) {
  const LidarScan truth = simulatedVlp16(clockwise);
  ASSERT_EQ(truth.points.size(), 16u * 1800u);
  LidarScan scan = truth;
  scan.has_time = false;
  scan.t_end = scan.t;
  for (LidarPoint& p : scan.points) p.time_offset = 0;
  ScanLayoutConfig config = ScanLayoutConfig::vlp16();
  config.spin = clockwise ? SpinDirection::kClockwise : SpinDirection::kCounterClockwise;
  const TimeInference result = inferTimes(scan, config);
  EXPECT_EQ(result.status, InferenceStatus::kOk);
  EXPECT_TRUE(scan.has_time);
  const double column_period = config.scan_period / config.columns;
  double worst = 0;
  for (std::size_t i = 0; i < scan.points.size(); ++i)
    worst = std::max(worst, std::abs(double(scan.points[i].time_offset) - truth.points[i].time_offset));
  EXPECT_LT(worst, column_period);
  EXPECT_NEAR(toSeconds(scan.t_end - truth.t_end), 0.0, column_period);
  EXPECT_LT(result.max_time_offset, config.scan_period);
}

TEST(ScanLayout, InferredTimesMatchTheSimulatorsWithinOneColumnPeriod) { checkTimesWithinOneColumn(false); }

TEST(ScanLayout, InferredTimesFollowAClockwiseSpinToo) { checkTimesWithinOneColumn(true); }

TEST(ScanLayout, RingsFromElevationReproduceVlp16RingsExactly) {
  const LidarScan truth = simulatedVlp16();
  LidarScan scan = truth;
  scan.has_ring = false;
  for (LidarPoint& p : scan.points) p.ring = 0;
  const RingInference result = inferRings(scan, ScanLayoutConfig::vlp16());
  EXPECT_EQ(result.status, InferenceStatus::kOk);
  EXPECT_EQ(result.rings_found, 16);
  EXPECT_EQ(result.clamped, 0u);
  EXPECT_TRUE(scan.has_ring);
  for (std::size_t i = 0; i < scan.points.size(); ++i) ASSERT_EQ(scan.points[i].ring, truth.points[i].ring) << i;
}

// The simulator's points re-ordered ring by ring (each ring in firing order), as KITTI stores them.
LidarScan ringOrdered(const LidarScan& column_major, bool top_down) {
  LidarScan scan = column_major;
  std::stable_sort(scan.points.begin(), scan.points.end(), [&](const LidarPoint& a, const LidarPoint& b) {
    return top_down ? a.ring > b.ring : a.ring < b.ring;
  });
  return scan;
}

TEST(ScanLayout, RingsFromOrderReproduceTheRingsOfARingOrderedScan) {
  for (const bool top_down : {false, true}) {
    const LidarScan truth = ringOrdered(simulatedVlp16(), top_down);
    LidarScan scan = truth;
    for (LidarPoint& p : scan.points) p.ring = 0;
    ScanLayoutConfig config = ScanLayoutConfig::vlp16();
    config.ring_source = RingSource::kOrder;
    config.order_top_down = top_down;
    const RingInference result = inferRings(scan, config);
    EXPECT_EQ(result.status, InferenceStatus::kOk) << top_down;
    EXPECT_EQ(result.rings_found, 16);
    for (std::size_t i = 0; i < scan.points.size(); ++i)
      ASSERT_EQ(scan.points[i].ring, truth.points[i].ring) << i << " top_down " << top_down;
  }
}

// A ring-ordered scan whose rings start a little before or after the first point's azimuth and jitter across it
// (as KITTI's do), with one degree between points.
LidarScan jitteryRings(int rings) {
  LidarScan scan;
  const double starts[] = {0.0, -0.05, 0.08, -0.02};
  for (int r = 0; r < rings; ++r) {
    const double start = starts[r % 4] * kDeg;
    for (int k = 0; k < 360; ++k) {
      double az = start + k * kDeg;
      if (k == 1) az = start - 0.03 * kDeg;  // back across the seam
      LidarPoint p;
      p.x = static_cast<float>(10 * std::cos(az));
      p.y = static_cast<float>(10 * std::sin(az));
      p.z = static_cast<float>(r);
      p.ring = static_cast<std::uint16_t>(r);
      scan.points.push_back(p);
    }
  }
  return scan;
}

TEST(ScanLayout, RingsFromOrderIgnoreJitterAcrossTheSeam) {
  const LidarScan truth = jitteryRings(8);
  LidarScan scan = truth;
  ScanLayoutConfig config = ScanLayoutConfig::vlp16();
  config.n_rings = 8;
  config.ring_source = RingSource::kOrder;
  const RingInference result = inferRings(scan, config);
  EXPECT_EQ(result.rings_found, 8);
  for (std::size_t i = 0; i < scan.points.size(); ++i) ASSERT_EQ(scan.points[i].ring, truth.points[i].ring) << i;
  // Fewer rings configured than present: the extra revolutions are clamped and the mismatch reported.
  config.n_rings = 6;
  scan = truth;
  const RingInference clamped = inferRings(scan, config);
  EXPECT_EQ(clamped.status, InferenceStatus::kRingCountMismatch);
  EXPECT_EQ(clamped.rings_found, 8);
  EXPECT_EQ(clamped.clamped, 2u * 360u);
}

TEST(ScanLayout, RingsFromOrderStepOverNonFinitePoints) {
  LidarScan scan = jitteryRings(4);
  for (std::size_t i = 0; i < scan.points.size(); i += 50) scan.points[i].x = std::numeric_limits<float>::quiet_NaN();
  const LidarScan truth = scan;
  ScanLayoutConfig config = ScanLayoutConfig::vlp16();
  config.n_rings = 4;
  config.ring_source = RingSource::kOrder;
  EXPECT_EQ(inferRings(scan, config).status, InferenceStatus::kOk);
  for (std::size_t i = 0; i < scan.points.size(); ++i) ASSERT_EQ(scan.points[i].ring, truth.points[i].ring) << i;
  const TimeInference times = inferTimes(scan, config);  // the first point is NaN: the start is the next one
  EXPECT_EQ(scan.points[0].time_offset, 0.0f);
  EXPECT_EQ(scan.points[1].time_offset, 0.0f);                                      // at -0.03 deg
  EXPECT_NEAR(scan.points[2].time_offset, config.scan_period * 2.03 / 360, 1e-7);  // at 2 deg
  EXPECT_LT(times.max_time_offset, config.scan_period);
}

// KITTI's HDL-64 .bin files list the beams one revolution each, from the top beam down, every revolution starting
// at the front (azimuth ~0) and turning counter-clockwise. Their beams are not uniformly spaced, so rings come from
// order; ring 0 (the lowest beam) is then the last revolution in the file.
TEST(ScanLayout, RingsFromOrderOnARealKittiScanGive64RingsOfIncreasingElevation) {
  const auto path = test::sharedData("kitti/sequences/00/velodyne/000000.bin");
  DROVER_REQUIRE_SHARED(path);
  LidarScan scan = io::readKittiBin(path.string(), 0, 0);
  const ScanLayoutConfig config = ScanLayoutConfig::kittiHdl64();
  const RingInference result = inferRings(scan, config);
  EXPECT_EQ(result.status, InferenceStatus::kOk);
  ASSERT_EQ(result.rings_found, 64);
  std::vector<double> sum(64, 0.0);
  std::vector<int> count(64, 0);
  for (const LidarPoint& p : scan.points) {
    sum[p.ring] += elevationOf(p);
    ++count[p.ring];
  }
  for (int r = 0; r < 64; ++r) ASSERT_GT(count[r], 500) << "ring " << r;
  for (int r = 1; r < 64; ++r) EXPECT_GT(sum[r] / count[r], sum[r - 1] / count[r - 1]) << "ring " << r;
  EXPECT_NEAR(sum[63] / count[63], 2.0 * kDeg, 1.0 * kDeg);     // top beam near +2 deg
  EXPECT_NEAR(sum[0] / count[0], -24.0 * kDeg, 1.0 * kDeg);     // bottom beam near -24.9 deg

  // Times follow the spin: within every ring they grow with point order. KITTI's azimuths (seen from the sensor's
  // centre, not from each laser) step back now and then, by up to several degrees on close objects seen by the
  // bottom beams: allow those, but no jump back across the sweep.
  const TimeInference times = inferTimes(scan, config);
  EXPECT_LT(times.max_time_offset, config.scan_period);
  const double ten_degrees = config.scan_period / 36;
  std::size_t backwards = 0, steps = 0;
  for (std::size_t i = 1; i < scan.points.size(); ++i) {
    if (scan.points[i].ring != scan.points[i - 1].ring) continue;
    ++steps;
    const double step = double(scan.points[i].time_offset) - scan.points[i - 1].time_offset;
    if (step < 0) ++backwards;
    EXPECT_GT(step, -ten_degrees) << "point " << i;
  }
  EXPECT_LT(backwards, steps / 100);
}

TEST(ScanLayout, SanitizeDropsAndCountsNonFiniteAndOutOfRangePointsKeepingOrder) {
  LidarScan scan;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float xs[] = {5, nan, 0.5f, 6, 200, inf, 7};
  for (float x : xs) {
    LidarPoint p;
    p.x = x;
    scan.points.push_back(p);
  }
  scan.points[1].y = 1;  // a NaN in x with finite y, z
  scan.points[5].x = 1;
  scan.points[5].z = -inf;
  const SanitizeResult result = sanitize(scan, ScanLayoutConfig::vlp16());
  EXPECT_EQ(result.non_finite, 2u);
  EXPECT_EQ(result.too_close, 1u);
  EXPECT_EQ(result.too_far, 1u);
  ASSERT_EQ(result.kept, 3u);
  ASSERT_EQ(scan.points.size(), 3u);
  EXPECT_EQ(scan.points[0].x, 5);
  EXPECT_EQ(scan.points[1].x, 6);
  EXPECT_EQ(scan.points[2].x, 7);
}

TEST(ScanLayout, EmptyScansAreReportedAndLeftUnchanged) {
  LidarScan scan;
  EXPECT_EQ(inferTimes(scan, ScanLayoutConfig::vlp16()).status, InferenceStatus::kEmpty);
  EXPECT_EQ(inferRings(scan, ScanLayoutConfig::kittiHdl64()).status, InferenceStatus::kEmpty);
  EXPECT_FALSE(scan.has_time);
  EXPECT_FALSE(scan.has_ring);
  EXPECT_EQ(sanitize(scan, ScanLayoutConfig::vlp16()).kept, 0u);
}

TEST(ScanLayout, InvalidConfigsAreRejectedNamingTheValue) {
  EXPECT_EQ(ScanLayoutConfig::vlp16().validate(), "");
  EXPECT_EQ(ScanLayoutConfig::kittiHdl64().validate(), "");
  ScanLayoutConfig c;
  c.n_rings = 0;
  EXPECT_NE(c.validate().find("n_rings"), std::string::npos);
  c = {};
  c.vertical_fov_max_deg = -20;
  EXPECT_NE(c.validate().find("vertical_fov_max_deg"), std::string::npos);
  c = {};
  c.scan_period = 0;
  EXPECT_NE(c.validate().find("scan_period"), std::string::npos);
  c = {};
  c.max_range = 0.5;
  EXPECT_NE(c.validate().find("max_range"), std::string::npos);
  LidarScan scan = simulatedVlp16();
  c = {};
  c.columns = 0;
  EXPECT_THROW(inferTimes(scan, c), std::invalid_argument);
  EXPECT_THROW(inferRings(scan, c), std::invalid_argument);
  EXPECT_THROW(sanitize(scan, c), std::invalid_argument);
}

}  // namespace
}  // namespace drover::lidar
