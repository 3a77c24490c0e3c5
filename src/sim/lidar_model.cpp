// Rotating multi-beam lidar by ray casting, column by column from the pose at each column's firing time.
#include "sim/lidar_model.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "sim/random.hpp"

namespace drover::sim {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

std::vector<double> uniformElevations(int count, double lo_deg, double hi_deg) {
  std::vector<double> e(count);
  for (int i = 0; i < count; ++i) e[i] = (lo_deg + (hi_deg - lo_deg) * i / (count - 1)) * kDeg;
  return e;
}

// VLP-32C (Velodyne "Puck 32MR" / VLP-32C user manual, laser elevation table), sorted ascending [deg]:
// dense 1/3 deg spacing around the horizon, sparse towards -25 and +15.
std::vector<double> vlp32Elevations() {
  const double deg[32] = {-25.0,  -15.639, -11.31, -8.843, -7.254, -6.148, -5.333, -4.667, -4.0,  -3.667, -3.333,
                          -3.0,   -2.667,  -2.333, -2.0,   -1.667, -1.333, -1.0,   -0.667, -0.333, 0.0,    0.333,
                          0.667,  1.0,     1.333,  1.667,  2.333,  3.333,  4.667,  7.0,    10.333, 15.0};
  std::vector<double> e(std::begin(deg), std::end(deg));
  for (double& v : e) v *= kDeg;
  return e;
}

// HDL-64E (KITTI's sensor), approximated by its two laser blocks: 32 lower lasers uniform over -24.9..-8.87 deg and
// 32 upper lasers at 1/3 deg spacing over -8.33..+2.0 deg (the real per-laser calibration varies slightly).
std::vector<double> hdl64Elevations() {
  std::vector<double> e = uniformElevations(32, -24.9, -8.87);
  const std::vector<double> upper = uniformElevations(32, -8.33, 2.0);
  e.insert(e.end(), upper.begin(), upper.end());
  return e;
}

// Firing time of column c after the sweep start [ns], rounded to the nearest nanosecond.
Time columnOffset(const LidarModelConfig& config, int c) {
  return static_cast<Time>(std::llround(static_cast<double>(c) * 1e9 / (config.rate_hz * config.columns)));
}

struct Slot {
  LidarPoint point;
  bool valid = false;
};

// Casts one column (all rings) from the lidar pose at the column's firing time into slots[0, rings).
void castColumn(const World& world, const Eigen::Isometry3d& T_world_lidar, const LidarModelConfig& config,
                std::uint64_t seed, std::uint64_t sweep_index, int c, float time_offset, Slot* slots) {
  const double sign = config.spin_clockwise ? -1.0 : 1.0;
  const double azimuth = sign * 2.0 * std::numbers::pi * c / config.columns;
  const double ca = std::cos(azimuth), sa = std::sin(azimuth);
  const int rings = static_cast<int>(config.elevations.size());
  for (int r = 0; r < rings; ++r) {
    const double ce = std::cos(config.elevations[r]), se = std::sin(config.elevations[r]);
    const Eigen::Vector3d d_lidar(ce * ca, ce * sa, se);
    const Ray ray{T_world_lidar.translation(), T_world_lidar.linear() * d_lidar};
    const auto hit = world.intersect(ray, 1e-4, config.max_range);
    if (!hit || hit->distance < config.min_range) continue;  // sky / out of range / inside the blind zone
    double range = hit->distance;
    const double reflectivity = hit->material->reflectivity;
    if (config.noise) {
      const auto key = [&](std::uint64_t k) {
        return hashKeys(seed, Stream::kLidar, sweep_index, static_cast<std::uint64_t>(c),
                        static_cast<std::uint64_t>(r), k);
      };
      const double q = range / config.max_range;
      const double p_drop = std::clamp(config.dropout_base + q * q * (1.0 - reflectivity), 0.0, 1.0);
      if (uniform01(key(1)) < p_drop) continue;
      range += config.range_noise_sigma * standardNormal(key(0));
      if (range <= 0.0) continue;
    }
    const Eigen::Vector3d p = d_lidar * range;
    Slot& s = slots[r];
    s.valid = true;
    s.point.x = static_cast<float>(p.x());
    s.point.y = static_cast<float>(p.y());
    s.point.z = static_cast<float>(p.z());
    const double cos_incidence = std::abs(ray.direction.dot(hit->normal));
    s.point.intensity = static_cast<float>(reflectivity * 255.0 * cos_incidence);
    s.point.time_offset = time_offset;
    s.point.ring = static_cast<std::uint16_t>(r);
  }
}

}  // namespace

LidarModelConfig LidarModelConfig::forModel(const std::string& model) {
  LidarModelConfig c;
  c.model = model;
  if (model == "vlp16") {
    c.elevations = uniformElevations(16, -15.0, 15.0);
    c.columns = 1800;
    c.max_range = 100.0;
  } else if (model == "vlp32") {
    c.elevations = vlp32Elevations();
    c.columns = 1800;
    c.max_range = 200.0;
  } else if (model == "hdl64") {
    c.elevations = hdl64Elevations();
    c.columns = 2083;  // 0.1728 deg at 10 Hz: ~133k rays, ~120k returns outdoors, like KITTI
    c.max_range = 120.0;
  } else {
    throw std::invalid_argument("LidarModelConfig::forModel: unknown model '" + model +
                                "' (known: vlp16, vlp32, hdl64)");
  }
  c.rate_hz = 10.0;
  return c;
}

std::string LidarModelConfig::validate() const {
  if (elevations.empty()) return "lidar: elevations is empty (use LidarModelConfig::forModel)";
  if (elevations.size() > 65535) return "lidar: too many rings (" + std::to_string(elevations.size()) + ")";
  for (std::size_t i = 0; i < elevations.size(); ++i) {
    if (!(std::abs(elevations[i]) < std::numbers::pi / 2))
      return "lidar: elevation " + std::to_string(elevations[i]) + " rad is not in (-pi/2, pi/2)";
    if (i > 0 && !(elevations[i] > elevations[i - 1]))
      return "lidar: elevations must be strictly ascending (ring " + std::to_string(i) + ")";
  }
  if (columns < 1) return "lidar: columns must be >= 1, got " + std::to_string(columns);
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) return "lidar: rate_hz must be > 0, got " + std::to_string(rate_hz);
  if (!(min_range >= 0.0)) return "lidar: min_range must be >= 0, got " + std::to_string(min_range);
  if (!(max_range > min_range) || !std::isfinite(max_range))
    return "lidar: max_range must be finite and > min_range, got " + std::to_string(max_range);
  if (!(range_noise_sigma >= 0.0)) return "lidar: range_noise_sigma must be >= 0, got " + std::to_string(range_noise_sigma);
  if (!(dropout_base >= 0.0 && dropout_base <= 1.0))
    return "lidar: dropout_base must be in [0, 1], got " + std::to_string(dropout_base);
  return "";
}

LidarScan simulateSweep(const World& world, const SplineTrajectory& trajectory, const Eigen::Isometry3d& T_body_lidar,
                        Time t_start, const LidarModelConfig& config, std::uint64_t seed, std::uint64_t sweep_index) {
  if (const std::string why = config.validate(); !why.empty()) throw std::invalid_argument("simulateSweep: " + why);
  const int rings = static_cast<int>(config.elevations.size());
  std::vector<Slot> slots(static_cast<std::size_t>(config.columns) * rings);
  tbb::parallel_for(tbb::blocked_range<int>(0, config.columns), [&](const tbb::blocked_range<int>& range) {
    for (int c = range.begin(); c != range.end(); ++c) {
      const Time offset = columnOffset(config, c);
      const Eigen::Isometry3d T_world_lidar = trajectory.pose(t_start + offset) * T_body_lidar;
      castColumn(world, T_world_lidar, config, seed, sweep_index, c, static_cast<float>(toSeconds(offset)),
                 &slots[static_cast<std::size_t>(c) * rings]);
    }
  });
  LidarScan scan;
  scan.t = t_start;
  scan.t_end = t_start + columnOffset(config, config.columns - 1);
  scan.has_time = true;
  scan.has_ring = true;
  scan.points.reserve(slots.size());
  for (const Slot& s : slots) {  // column-major, ring within column: the same order for any thread count
    if (s.valid) scan.points.push_back(s.point);
  }
  return scan;
}

}  // namespace drover::sim
