#include "lidar/scan_layout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace drover::lidar {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;
constexpr double kDegToRad = std::numbers::pi / 180.0;

void requireValid(const ScanLayoutConfig& config, const char* who) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument(std::string(who) + ": invalid ScanLayoutConfig: " + error);
}

double azimuthOf(const LidarPoint& p) { return std::atan2(static_cast<double>(p.y), static_cast<double>(p.x)); }

// The azimuth of the first point with a finite one (0 when none): the sweep's start.
double startAzimuth(const LidarScan& scan) {
  for (const LidarPoint& p : scan.points)
    if (const double az = azimuthOf(p); std::isfinite(az)) return az;
  return 0;
}

double spinSign(const ScanLayoutConfig& config) {
  return config.spin == SpinDirection::kCounterClockwise ? 1.0 : -1.0;
}

// Angle in [0, 2 pi).
double wrapTwoPi(double a) {
  a = std::fmod(a, kTwoPi);
  if (a < 0) a += kTwoPi;
  return a < kTwoPi ? a : 0.0;  // -1e-17 + 2 pi rounds to 2 pi
}
// Angle in [-pi, pi).
double wrapPi(double a) { return wrapTwoPi(a + std::numbers::pi) - std::numbers::pi; }

RingInference ringsFromElevation(LidarScan& scan, const ScanLayoutConfig& config) {
  RingInference result;
  const double lo = config.vertical_fov_min_deg * kDegToRad, hi = config.vertical_fov_max_deg * kDegToRad;
  const double per_ring = (config.n_rings - 1) / (hi - lo);  // rings per radian
  std::vector<char> seen(static_cast<std::size_t>(config.n_rings), 0);
  for (LidarPoint& p : scan.points) {
    const double horizontal = std::hypot(static_cast<double>(p.x), static_cast<double>(p.y));
    const double elevation = std::atan2(static_cast<double>(p.z), horizontal);
    const long ring = std::lround((elevation - lo) * per_ring);
    const long clamped = std::clamp(ring, 0L, static_cast<long>(config.n_rings - 1));
    if (clamped != ring) ++result.clamped;
    p.ring = static_cast<std::uint16_t>(clamped);
    seen[static_cast<std::size_t>(clamped)] = 1;
  }
  result.rings_found = static_cast<int>(std::count(seen.begin(), seen.end(), 1));
  return result;
}

// One revolution per ring: a new ring starts where the azimuth relative to the first point's (shifted by the seam
// tolerance) drops from near 2 pi to near 0, provided the current ring has already turned through more than pi.
// The accumulated turn uses wrapped increments, so back-and-forth jitter across the seam does not count.
RingInference ringsFromOrder(LidarScan& scan, const ScanLayoutConfig& config) {
  RingInference result;
  const double sign = spinSign(config), margin = config.seam_tolerance_deg * kDegToRad;
  const double az0 = startAzimuth(scan);
  double previous_az = az0, previous_rel = margin, turned = 0;
  int order = 0;
  const int last = config.n_rings - 1;
  for (LidarPoint& p : scan.points) {
    // A non-finite point keeps the current ring and leaves the seam detection untouched.
    if (const double az = azimuthOf(p); std::isfinite(az)) {
      const double rel = wrapTwoPi(sign * (az - az0) + margin);
      if (previous_rel - rel > std::numbers::pi && turned > std::numbers::pi) {
        ++order;
        turned = 0;
      } else {
        turned += sign * wrapPi(az - previous_az);
      }
      previous_az = az;
      previous_rel = rel;
    }
    const int clamped = std::min(order, last);
    if (clamped != order) ++result.clamped;
    p.ring = static_cast<std::uint16_t>(config.order_top_down ? last - clamped : clamped);
  }
  result.rings_found = order + 1;
  if (result.rings_found != config.n_rings) result.status = InferenceStatus::kRingCountMismatch;
  return result;
}

}  // namespace

ScanLayoutConfig ScanLayoutConfig::vlp16() { return ScanLayoutConfig{}; }

ScanLayoutConfig ScanLayoutConfig::kittiHdl64() {
  ScanLayoutConfig c;
  c.n_rings = 64;
  c.vertical_fov_min_deg = -24.9;
  c.vertical_fov_max_deg = 2.0;
  c.columns = 2083;
  c.ring_source = RingSource::kOrder;
  c.order_top_down = true;
  c.max_range = 120.0;
  return c;
}

std::string ScanLayoutConfig::validate() const {
  if (n_rings < 1 || n_rings > 65535) return "n_rings must be in [1, 65535], got " + std::to_string(n_rings);
  if (!std::isfinite(vertical_fov_min_deg) || !std::isfinite(vertical_fov_max_deg) ||
      vertical_fov_min_deg < -90 || vertical_fov_max_deg > 90)
    return "vertical FOV must be finite within [-90, 90] deg, got [" + std::to_string(vertical_fov_min_deg) + ", " +
           std::to_string(vertical_fov_max_deg) + "]";
  if (n_rings > 1 && !(vertical_fov_max_deg > vertical_fov_min_deg))
    return "vertical_fov_max_deg must exceed vertical_fov_min_deg, got " + std::to_string(vertical_fov_max_deg) +
           " <= " + std::to_string(vertical_fov_min_deg);
  if (columns < 1) return "columns must be >= 1, got " + std::to_string(columns);
  if (!std::isfinite(scan_period) || scan_period <= 0)
    return "scan_period must be finite and > 0, got " + std::to_string(scan_period);
  if (!std::isfinite(seam_tolerance_deg) || seam_tolerance_deg < 0 || seam_tolerance_deg >= 90)
    return "seam_tolerance_deg must be in [0, 90), got " + std::to_string(seam_tolerance_deg);
  if (!std::isfinite(min_range) || min_range < 0)
    return "min_range must be finite and >= 0, got " + std::to_string(min_range);
  if (!(max_range > min_range)) return "max_range must exceed min_range, got " + std::to_string(max_range);
  return {};
}

TimeInference inferTimes(LidarScan& scan, const ScanLayoutConfig& config) {
  requireValid(config, "inferTimes");
  TimeInference result;
  if (scan.points.empty()) {
    result.status = InferenceStatus::kEmpty;
    return result;
  }
  const double sign = spinSign(config), margin = config.seam_tolerance_deg * kDegToRad;
  const double az0 = startAzimuth(scan);
  const double seconds_per_radian = config.scan_period / kTwoPi;
  double latest = 0;
  for (LidarPoint& p : scan.points) {
    // Turned through since the start, in [-margin, 2 pi - margin); within the tolerance before it means "at it".
    const double az = azimuthOf(p);
    const double turned =
        std::isfinite(az) ? std::max(0.0, wrapTwoPi(sign * (az - az0) + margin) - margin) : 0.0;
    const double offset = turned * seconds_per_radian;
    p.time_offset = static_cast<float>(offset);
    latest = std::max(latest, offset);
  }
  result.max_time_offset = latest;
  scan.has_time = true;
  scan.t_end = scan.t + fromSeconds(latest);
  return result;
}

RingInference inferRings(LidarScan& scan, const ScanLayoutConfig& config) {
  requireValid(config, "inferRings");
  if (scan.points.empty()) {
    RingInference result;
    result.status = InferenceStatus::kEmpty;
    return result;
  }
  RingInference result = config.ring_source == RingSource::kElevation ? ringsFromElevation(scan, config)
                                                                      : ringsFromOrder(scan, config);
  scan.has_ring = true;
  return result;
}

SanitizeResult sanitize(LidarScan& scan, const ScanLayoutConfig& config) {
  requireValid(config, "sanitize");
  SanitizeResult result;
  const double min2 = config.min_range * config.min_range, max2 = config.max_range * config.max_range;
  std::erase_if(scan.points, [&](const LidarPoint& p) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      ++result.non_finite;
      return true;
    }
    const double r2 = double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z;
    if (r2 < min2) ++result.too_close;
    if (r2 > max2) ++result.too_far;
    return r2 < min2 || r2 > max2;
  });
  result.kept = scan.points.size();
  return result;
}

}  // namespace drover::lidar
