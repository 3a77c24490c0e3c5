#include "loop/scan_context.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace drover::loop {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

int wrapShift(int shift, int sectors) { return ((shift % sectors) + sectors) % sectors; }

void requireSameShape(const ScanContext& a, const ScanContext& b) {
  if (a.image.rows() != b.image.rows() || a.image.cols() != b.image.cols() || a.image.cols() == 0)
    throw std::invalid_argument("scan context shapes differ or are empty");
}

}  // namespace

std::string ScanContextConfig::validate() const {
  if (rings < 1 || sectors < 2) return "rings must be >= 1 and sectors >= 2";
  if (!std::isfinite(max_radius) || max_radius <= 0) return "max_radius must be finite and > 0 m";
  if (!std::isfinite(sensor_height)) return "sensor_height must be finite";
  if (!std::isfinite(threshold) || threshold <= 0 || threshold > 2) return "threshold must be in (0, 2]";
  if (search_radius < 0) return "search_radius must be >= 0";
  return {};
}

ScanContext makeScanContext(const lidar::PointCloud& cloud, const ScanContextConfig& config) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("scan context config: " + e);
  ScanContext sc;
  sc.image = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  sc.occupied = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  const double ring_width = config.max_radius / config.rings, sector_width = kTwoPi / config.sectors;
  for (const Eigen::Vector3f& p : cloud) {
    if (!p.allFinite()) continue;
    const double r = std::hypot(double(p.x()), double(p.y()));
    if (r >= config.max_radius || r <= 0) continue;
    double theta = std::atan2(double(p.y()), double(p.x()));
    if (theta < 0) theta += kTwoPi;
    const int ring = std::min(static_cast<int>(r / ring_width), config.rings - 1);
    const int sector = std::min(static_cast<int>(theta / sector_width), config.sectors - 1);
    const float h = static_cast<float>(p.z() + config.sensor_height);
    float& cell = sc.image(ring, sector);
    if (sc.occupied(ring, sector) == 0.0f || h > cell) cell = h;
    sc.occupied(ring, sector) = 1.0f;
  }
  sc.ring_key = sc.image.rowwise().mean();
  sc.sector_key = sc.image.colwise().mean().transpose();
  return sc;
}

double columnDistance(const ScanContext& a, const ScanContext& b, int shift) {
  requireSameShape(a, b);
  const int sectors = static_cast<int>(a.image.cols());
  double sum = 0;
  int count = 0;
  for (int j = 0; j < sectors; ++j) {
    const int k = wrapShift(j - shift, sectors);
    const double na = a.image.col(j).norm(), nb = b.image.col(k).norm();
    if (na == 0 || nb == 0) continue;
    sum += 1.0 - a.image.col(j).dot(b.image.col(k)) / (na * nb);
    ++count;
  }
  return count == 0 ? 1.0 : sum / count;
}

namespace {

ShiftMatch searchShifts(const ScanContext& a, const ScanContext& b, int first, int count) {
  const int sectors = static_cast<int>(a.image.cols());
  ShiftMatch best;
  best.distance = 2.0;
  for (int i = 0; i < count; ++i) {
    const int shift = wrapShift(first + i, sectors);
    const double d = columnDistance(a, b, shift);
    ++best.evaluated;
    if (d < best.distance) {
      best.distance = d;
      best.shift = shift;
    }
  }
  best.yaw = yawFromShift(best.shift, sectors);
  return best;
}

}  // namespace

ShiftMatch fullShiftSearch(const ScanContext& a, const ScanContext& b) {
  requireSameShape(a, b);
  return searchShifts(a, b, 0, static_cast<int>(a.image.cols()));
}

ShiftMatch narrowedShiftSearch(const ScanContext& a, const ScanContext& b, std::optional<double> yaw_prior,
                               const ScanContextConfig& config) {
  requireSameShape(a, b);
  const int sectors = static_cast<int>(a.image.cols());
  if (yaw_prior && std::isfinite(*yaw_prior) && 2 * config.search_radius + 1 < sectors) {
    const int center = shiftFromYaw(*yaw_prior, sectors);
    ShiftMatch m = searchShifts(a, b, center - config.search_radius, 2 * config.search_radius + 1);
    m.narrowed = true;
    if (m.distance < config.threshold) return m;
    const int evaluated = m.evaluated;
    m = fullShiftSearch(a, b);
    m.fell_back = true;
    m.evaluated += evaluated;
    return m;
  }
  return fullShiftSearch(a, b);
}

double yawFromShift(int shift, int sectors) {
  double yaw = wrapShift(shift, sectors) * kTwoPi / sectors;
  if (yaw > std::numbers::pi) yaw -= kTwoPi;
  return yaw;
}

int shiftFromYaw(double yaw, int sectors) {
  return wrapShift(static_cast<int>(std::lround(yaw / (kTwoPi / sectors))), sectors);
}

}  // namespace drover::loop
