// Lidar model: exact ranges to known geometry, beam tables, motion distortion that ground truth undoes exactly,
// point timing, dropout statistics, determinism.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <set>
#include <stdexcept>

#include "sim/lidar_model.hpp"
#include "support/units.hpp"

namespace drover::sim {
namespace {

using ::drover::test::kSec;
using ::drover::test::kDeg;

// A trajectory sampled every 0.1 s over [0, 2] s from f(t [s]).
SplineTrajectory trajectoryOf(const std::function<PathSample(double)>& f) {
  std::vector<PathSample> samples;
  for (int k = 0; k <= 20; ++k) {
    PathSample s = f(0.1 * k);
    s.t = k * kSec / 10;
    samples.push_back(s);
  }
  return SplineTrajectory(samples);
}

SplineTrajectory standingStill(const Eigen::Vector3d& p) {
  return trajectoryOf([&](double) {
    PathSample s;
    s.p_world = p;
    return s;
  });
}

Material withReflectivity(float reflectivity) {
  Material m;
  m.reflectivity = reflectivity;
  return m;
}

// A vertical wall x = d (normal -x), 1 km wide and tall, and nothing else.
World wallAt(double d, float reflectivity = 0.5f) {
  World w;
  Rectangle r;
  r.T_world_rect.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  r.T_world_rect.translation() = Eigen::Vector3d(d, 0, 0);
  r.half_size = Eigen::Vector2d(500, 500);
  w.addRectangle(r, withReflectivity(reflectivity));
  w.build();
  return w;
}

LidarModelConfig exact(const std::string& model) {
  LidarModelConfig c = LidarModelConfig::forModel(model);
  c.noise = false;
  return c;
}

// Azimuth [rad] of the column a point's time offset belongs to (column = offset * rate * columns).
double azimuthOf(const LidarModelConfig& c, double time_offset) {
  return 2 * std::numbers::pi * std::round(time_offset * c.rate_hz * c.columns) / c.columns;
}

TEST(LidarModel, PlaneAtKnownDistanceIsReturnedOnEveryRing) {
  const double d = 5.0;
  const World world = wallAt(d);
  const SplineTrajectory still = standingStill({0, 0, 0});
  for (const std::string model : {"vlp16", "vlp32", "hdl64"}) {
    const LidarModelConfig c = exact(model);
    const LidarScan scan = simulateSweep(world, still, Eigen::Isometry3d::Identity(), kSec / 2, c, 1, 0);
    std::vector<int> per_ring(c.elevations.size(), 0);
    for (const LidarPoint& p : scan.points) {
      const double e = c.elevations.at(p.ring), az = azimuthOf(c, p.time_offset);
      const double range = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
      ASSERT_NEAR(range, d / (std::cos(e) * std::cos(az)), 1e-6 * range) << model << " ring " << p.ring;
      ASSERT_NEAR(p.x, d, 1e-6);
      ++per_ring[p.ring];
    }
    for (std::size_t r = 0; r < per_ring.size(); ++r) {
      // Columns with |az| < acos(d / (max_range cos e)) reach the wall: nearly half of them.
      const double half_width = std::acos(d / (c.max_range * std::cos(c.elevations[r])));
      const int expected = static_cast<int>(std::round(2 * half_width / (2 * std::numbers::pi) * c.columns));
      EXPECT_NEAR(per_ring[r], expected, 2) << model << " ring " << r;
    }
  }
}

TEST(LidarModel, RingCountAndElevationsMatchTheModel) {
  const auto check = [](const std::string& model, std::size_t rings, double lo_deg, double hi_deg, int columns) {
    const LidarModelConfig c = LidarModelConfig::forModel(model);
    EXPECT_EQ(c.validate(), "");
    ASSERT_EQ(c.elevations.size(), rings) << model;
    EXPECT_NEAR(c.elevations.front(), lo_deg * kDeg, 1e-12) << model;
    EXPECT_NEAR(c.elevations.back(), hi_deg * kDeg, 1e-12) << model;
    EXPECT_EQ(c.columns, columns) << model;
    EXPECT_DOUBLE_EQ(c.rate_hz, 10.0);
  };
  check("vlp16", 16, -15, 15, 1800);
  check("vlp32", 32, -25, 15, 1800);
  check("hdl64", 64, -24.9, 2.0, 2083);
  const LidarModelConfig vlp16 = LidarModelConfig::forModel("vlp16");
  for (std::size_t r = 1; r < 16; ++r) EXPECT_NEAR(vlp16.elevations[r] - vlp16.elevations[r - 1], 2 * kDeg, 1e-12);
  const LidarModelConfig vlp32 = LidarModelConfig::forModel("vlp32");
  EXPECT_NEAR(vlp32.elevations[20], 0.0, 1e-12);                                   // a horizontal beam
  EXPECT_NEAR(vlp32.elevations[21] - vlp32.elevations[20], 0.333 * kDeg, 1e-12);  // dense near the horizon
  EXPECT_GT(vlp32.elevations[1] - vlp32.elevations[0], 9 * kDeg);                 // sparse at the bottom
  EXPECT_DOUBLE_EQ(vlp32.max_range, 200.0);
  EXPECT_THROW(LidarModelConfig::forModel("os1"), std::invalid_argument);

  // The beams the scan reports are at those elevations: measured from the points of a sweep in a closed room.
  World room;
  Box box;
  box.half_extents = Eigen::Vector3d(20, 20, 20);
  room.addBox(box, Material{});
  room.build();
  const SplineTrajectory still = standingStill({1, 2, 0.5});
  for (const std::string model : {"vlp16", "vlp32", "hdl64"}) {
    const LidarModelConfig c = exact(model);
    const LidarScan scan = simulateSweep(room, still, Eigen::Isometry3d::Identity(), kSec / 2, c, 1, 0);
    EXPECT_EQ(scan.points.size(), c.elevations.size() * c.columns) << model;  // every ray hits a wall
    std::set<int> rings;
    for (const LidarPoint& p : scan.points) {
      rings.insert(p.ring);
      ASSERT_NEAR(std::atan2(double(p.z), std::hypot(double(p.x), double(p.y))), c.elevations[p.ring], 1e-6) << model;
    }
    EXPECT_EQ(rings.size(), c.elevations.size()) << model;
  }
}

TEST(LidarModel, PointTimesIncreaseWithColumnAndSpanTheSweep) {
  const World world = wallAt(3.0);
  const LidarModelConfig c = exact("vlp16");
  const Time t0 = kSec / 2;
  const LidarScan scan = simulateSweep(world, standingStill({0, 0, 0}), Eigen::Isometry3d::Identity(), t0, c, 1, 0);
  EXPECT_TRUE(scan.has_time);
  EXPECT_TRUE(scan.has_ring);
  EXPECT_EQ(scan.t, t0);
  EXPECT_EQ(scan.t_end, t0 + Time{100'000'000} * 1799 / 1800);  // period * (columns - 1) / columns, rounded to ns
  ASSERT_FALSE(scan.points.empty());
  for (std::size_t i = 1; i < scan.points.size(); ++i) {
    const LidarPoint &a = scan.points[i - 1], &b = scan.points[i];
    ASSERT_GE(b.time_offset, a.time_offset);
    if (b.time_offset == a.time_offset) {
      ASSERT_GT(b.ring, a.ring);  // ring order within a column
    }
  }
  for (const LidarPoint& p : scan.points) {
    // Column index from the azimuth (the wall faces +x, so |azimuth| < 90 deg): time = column / (columns * rate).
    const double az = std::atan2(double(p.y), double(p.x));
    const double column = std::round((az < 0 ? az + 2 * std::numbers::pi : az) / (2 * std::numbers::pi) * c.columns);
    ASSERT_NEAR(p.time_offset, column / (c.columns * c.rate_hz), 1e-8);
  }
}

// A closed room: a box seen from inside, 6 m x 4 m x 3 m.
World room() {
  World w;
  Box b;
  b.T_world_box.translation() = Eigen::Vector3d(0, 0, 1.5);
  b.half_extents = Eigen::Vector3d(3, 2, 1.5);
  w.addBox(b, Material{});
  w.build();
  return w;
}

// Distance of a world point to the room's surface [m].
double distanceToRoom(const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = (p - Eigen::Vector3d(0, 0, 1.5)).cwiseAbs() - Eigen::Vector3d(3, 2, 1.5);
  return std::abs(q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0));
}

TEST(LidarModel, SweepWhileTurningIsDistortedAndGroundTruthPerPointPosesUndistortItExactly) {
  const World world = room();
  // Turning at 90 deg/s while creeping forward at 0.5 m/s, lidar 0.3 m above the body and yawed 10 deg.
  const SplineTrajectory turning = trajectoryOf([](double t) {
    PathSample s;
    s.p_world = Eigen::Vector3d(-0.5 + 0.5 * t, 0.2, 1.0);
    s.yaw = std::numbers::pi / 2 * t;
    return s;
  });
  Eigen::Isometry3d T_body_lidar = Eigen::Isometry3d::Identity();
  T_body_lidar.translation() = Eigen::Vector3d(0.1, 0, 0.3);
  T_body_lidar.linear() = Eigen::AngleAxisd(10 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const LidarModelConfig c = exact("vlp16");
  const Time t0 = kSec / 2;
  const LidarScan scan = simulateSweep(world, turning, T_body_lidar, t0, c, 1, 0);
  ASSERT_EQ(scan.points.size(), 16u * 1800u);
  const Eigen::Isometry3d T_start = turning.pose(t0) * T_body_lidar;
  double naive_max = 0, exact_max = 0;
  for (const LidarPoint& p : scan.points) {
    const Eigen::Vector3d p_lidar(p.x, p.y, p.z);
    naive_max = std::max(naive_max, distanceToRoom(T_start * p_lidar));
    const Time t = scan.t + fromSeconds(p.time_offset);
    exact_max = std::max(exact_max, distanceToRoom(turning.pose(t) * T_body_lidar * p_lidar));
  }
  EXPECT_GT(naive_max, 0.2);   // ~9 deg of rotation over the sweep at 2-3 m range
  EXPECT_LT(exact_max, 1e-6);  // float point coordinates and time offsets are the only error
}

TEST(LidarModel, IntensityFollowsReflectivityAndIncidence) {
  const World world = wallAt(4.0, 0.8f);
  const LidarModelConfig c = exact("vlp16");
  const LidarScan scan = simulateSweep(world, standingStill({0, 0, 0}), Eigen::Isometry3d::Identity(), kSec / 2, c, 1, 0);
  for (const LidarPoint& p : scan.points) {
    const double cos_incidence = std::cos(c.elevations[p.ring]) * std::cos(azimuthOf(c, p.time_offset));
    ASSERT_NEAR(p.intensity, 0.8 * 255 * cos_incidence, 1e-3);
  }
}

TEST(LidarModel, RangeNoiseHasTheConfiguredSigma) {
  const double d = 5.0;
  const World world = wallAt(d, 1.0f);  // reflectivity 1: dropout is dropout_base only
  LidarModelConfig c = LidarModelConfig::forModel("vlp16");
  c.range_noise_sigma = 0.03;
  c.dropout_base = 0.0;
  const LidarScan scan = simulateSweep(world, standingStill({0, 0, 0}), Eigen::Isometry3d::Identity(), kSec / 2, c, 9, 3);
  double sum = 0, sum2 = 0;
  for (const LidarPoint& p : scan.points) {
    const double e = c.elevations[p.ring], az = azimuthOf(c, p.time_offset);
    const double err = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z) -
                       d / (std::cos(e) * std::cos(az));
    ASSERT_LT(std::abs(err), 6 * c.range_noise_sigma);
    sum += err;
    sum2 += err * err;
  }
  const double n = static_cast<double>(scan.points.size());
  ASSERT_GT(n, 10000);
  EXPECT_NEAR(sum / n, 0.0, 5 * c.range_noise_sigma / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sum2 / n), c.range_noise_sigma, 0.03 * c.range_noise_sigma);
}

// Returns kept with noise on versus the expectation sum(1 - p) over the noise-free returns.
struct DropoutStats {
  double kept_fraction, expected_kept, kept, sigma;
};
DropoutStats dropoutAt(double d, float reflectivity) {
  const World world = wallAt(d, reflectivity);
  const SplineTrajectory still = standingStill({0, 0, 0});
  const LidarModelConfig exact_config = exact("vlp16");
  LidarModelConfig c = LidarModelConfig::forModel("vlp16");
  const LidarScan all = simulateSweep(world, still, Eigen::Isometry3d::Identity(), kSec / 2, exact_config, 4, 0);
  const LidarScan kept = simulateSweep(world, still, Eigen::Isometry3d::Identity(), kSec / 2, c, 4, 0);
  double expected = 0, var = 0;
  for (const LidarPoint& p : all.points) {
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z) / c.max_range;
    const double drop = std::clamp(c.dropout_base + r * r * (1.0 - reflectivity), 0.0, 1.0);
    expected += 1.0 - drop;
    var += drop * (1.0 - drop);
  }
  const double n_kept = static_cast<double>(kept.points.size());
  return {n_kept / static_cast<double>(all.points.size()), expected, n_kept, std::sqrt(var)};
}

TEST(LidarModel, DropoutsRiseWithDistanceAndWithLowReflectivity) {
  const DropoutStats near_dark = dropoutAt(10.0, 0.05f), far_dark = dropoutAt(60.0, 0.05f);
  const DropoutStats far_bright = dropoutAt(60.0, 0.95f);
  for (const DropoutStats& s : {near_dark, far_dark, far_bright}) {
    EXPECT_NEAR(s.kept, s.expected_kept, 5 * s.sigma + 1);  // the header's formula, statistically
  }
  EXPECT_GT(near_dark.kept_fraction, far_dark.kept_fraction + 0.2);
  EXPECT_GT(far_bright.kept_fraction, far_dark.kept_fraction + 0.2);
  EXPECT_GT(far_bright.kept_fraction, 0.9);
}

bool samePoints(const LidarScan& a, const LidarScan& b) {
  if (a.points.size() != b.points.size()) return false;
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    const LidarPoint &p = a.points[i], &q = b.points[i];
    if (p.x != q.x || p.y != q.y || p.z != q.z || p.intensity != q.intensity || p.time_offset != q.time_offset ||
        p.ring != q.ring)
      return false;
  }
  return true;
}

TEST(LidarModel, SameSeedGivesIdenticalScansForAnyThreadCount) {
  const World world = room();
  const SplineTrajectory still = standingStill({0.5, -0.3, 1.2});
  const LidarModelConfig c = LidarModelConfig::forModel("vlp16");
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const LidarScan a = simulateSweep(world, still, I, kSec / 2, c, 7, 2);
  LidarScan serial;
  tbb::task_arena one_thread(1);
  one_thread.execute([&] { serial = simulateSweep(world, still, I, kSec / 2, c, 7, 2); });
  EXPECT_TRUE(samePoints(a, serial));
  EXPECT_FALSE(samePoints(a, simulateSweep(world, still, I, kSec / 2, c, 8, 2)));  // other seed
  EXPECT_FALSE(samePoints(a, simulateSweep(world, still, I, kSec / 2, c, 7, 3)));  // other sweep
}

TEST(LidarModel, InvalidConfigAndTimesOutsideTheTrajectoryThrow) {
  const World world = room();
  const SplineTrajectory still = standingStill({0, 0, 1});
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  LidarModelConfig c = LidarModelConfig::forModel("vlp16");
  c.elevations = {0.1, 0.0};
  EXPECT_NE(c.validate(), "");
  EXPECT_THROW(simulateSweep(world, still, I, 0, c, 1, 0), std::invalid_argument);
  c = LidarModelConfig::forModel("vlp16");
  c.columns = 0;
  EXPECT_THROW(simulateSweep(world, still, I, 0, c, 1, 0), std::invalid_argument);
  c = LidarModelConfig::forModel("vlp16");
  EXPECT_THROW(simulateSweep(world, still, I, 2 * kSec - kSec / 20, c, 1, 0), std::out_of_range);
}

}  // namespace
}  // namespace drover::sim
