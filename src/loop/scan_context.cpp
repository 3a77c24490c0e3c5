#include "loop/scan_context.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "geometry/so3.hpp"

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
  if (!std::isfinite(sensor_height) || !std::isfinite(ground_lift))
    return "sensor_height and ground_lift must be finite";
  if (!std::isfinite(threshold) || threshold <= 0 || threshold > 2) return "threshold must be in (0, 2]";
  if (search_radius < 0) return "search_radius must be >= 0";
  if (!std::isfinite(lateral_step) || lateral_step <= 0) return "lateral_step must be finite and > 0 m";
  if (lateral_steps < 0 || lateral_steps > 5) return "lateral_steps must be in [0, 5]";
  return {};
}

namespace {

void fillUnitColumns(ScanContext& sc) {
  sc.column_norms = sc.image.colwise().norm().transpose();
  sc.unit_columns = sc.image;
  for (Eigen::Index j = 0; j < sc.image.cols(); ++j)
    if (sc.column_norms(j) > 0) sc.unit_columns.col(j) /= sc.column_norms(j);
}

bool hasUnitColumns(const ScanContext& sc) {
  return sc.unit_columns.rows() == sc.image.rows() && sc.unit_columns.cols() == sc.image.cols() &&
         sc.column_norms.size() == sc.image.cols();
}

// The descriptor of the points p - origin (origin: the sensor's real or virtual x-y position [m]), heights + lift.
ScanContext describe(const lidar::PointCloud& cloud, const ScanContextConfig& config, const Eigen::Vector2f& origin,
                     double lift_m) {
  ScanContext sc;
  sc.image = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  sc.occupied = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  // Float arithmetic throughout: 120k points per scan, and bin edges need no double precision.
  const float max_r = static_cast<float>(config.max_radius), max_r2 = max_r * max_r;
  const float rings_per_m = static_cast<float>(config.rings) / max_r;
  const float sectors_per_rad = static_cast<float>(config.sectors / kTwoPi), two_pi = static_cast<float>(kTwoPi);
  const float lift = static_cast<float>(lift_m);
  for (const Eigen::Vector3f& p : cloud) {
    const float x = p.x() - origin.x(), y = p.y() - origin.y();
    const float r2 = x * x + y * y;
    if (!(r2 < max_r2) || r2 <= 0.0f || !std::isfinite(p.z())) continue;  // also drops NaN x/y
    float theta = std::atan2(y, x);
    if (theta < 0) theta += two_pi;
    const int ring = std::min(static_cast<int>(std::sqrt(r2) * rings_per_m), config.rings - 1);
    const int sector = std::min(static_cast<int>(theta * sectors_per_rad), config.sectors - 1);
    const float h = p.z() + lift;
    float& cell = sc.image(ring, sector);
    float& occ = sc.occupied(ring, sector);
    if (occ == 0.0f || h > cell) cell = h;
    occ = 1.0f;
  }
  sc.ring_key = sc.image.rowwise().mean();
  sc.sector_key = sc.image.colwise().mean().transpose();
  fillUnitColumns(sc);
  return sc;
}

void requireValid(const ScanContextConfig& config) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("scan context config: " + e);
}

}  // namespace

double heightLift(const lidar::PointCloud& cloud, const ScanContextConfig& config) {
  if (!config.auto_height) return config.sensor_height;
  std::vector<float> z;
  for (const Eigen::Vector3f& p : cloud) {
    const float r2 = p.x() * p.x() + p.y() * p.y();
    if (r2 > 4.0f && r2 < 400.0f && std::isfinite(p.z())) z.push_back(p.z());
  }
  if (z.size() < 20) return config.sensor_height;  // too little to tell: the configured mount
  const auto k = z.begin() + static_cast<std::ptrdiff_t>(z.size() / 20);
  std::nth_element(z.begin(), k, z.end());
  return config.ground_lift - static_cast<double>(*k);
}

ScanContext makeScanContext(const lidar::PointCloud& cloud, const ScanContextConfig& config) {
  requireValid(config);
  return describe(cloud, config, Eigen::Vector2f::Zero(), heightLift(cloud, config));
}

AugmentedScanContext makeAugmentedScanContext(const lidar::PointCloud& cloud, const ScanContextConfig& config) {
  requireValid(config);
  AugmentedScanContext out;
  out.offsets.emplace_back(0.0f, 0.0f);  // the real position first
  const int k = config.lateral_steps;
  for (int i = -k; i <= k; ++i)
    for (int j = -k; j <= k; ++j)
      if (i != 0 || j != 0) out.offsets.emplace_back(float(i * config.lateral_step), float(j * config.lateral_step));
  const double lift = heightLift(cloud, config);
  for (const Eigen::Vector2f& o : out.offsets) out.descriptors.push_back(describe(cloud, config, o, lift));
  return out;
}

double columnDistance(const ScanContext& a_in, const ScanContext& b_in, int shift) {
  requireSameShape(a_in, b_in);
  // Hand-made descriptors may lack the unit columns: complete a copy (makeScanContext's never need it).
  ScanContext a_own, b_own;
  const ScanContext* a = &a_in;
  const ScanContext* b = &b_in;
  if (!hasUnitColumns(a_in)) {
    a_own = a_in;
    fillUnitColumns(a_own);
    a = &a_own;
  }
  if (!hasUnitColumns(b_in)) {
    b_own = b_in;
    fillUnitColumns(b_own);
    b = &b_own;
  }
  const int sectors = static_cast<int>(a->image.cols());
  double sum = 0;
  int count = 0;
  for (int j = 0; j < sectors; ++j) {
    const int k = wrapShift(j - shift, sectors);
    if (a->column_norms(j) == 0 || b->column_norms(k) == 0) continue;
    sum += 1.0 - static_cast<double>(a->unit_columns.col(j).dot(b->unit_columns.col(k)));
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

ShiftMatch narrowedShiftSearch(const ScanContext& a, const ScanContext& b, std::optional<YawPrior> prior,
                               const ScanContextConfig& config) {
  requireSameShape(a, b);
  const int sectors = static_cast<int>(a.image.cols());
  const int r = config.search_radius;
  if (!prior || !std::isfinite(prior->yaw) || 2 * r + 1 >= sectors) return fullShiftSearch(a, b);
  const int center = shiftFromYaw(prior->yaw, sectors);
  ShiftMatch m = searchShifts(a, b, center - r, 2 * r + 1);
  m.narrowed = true;
  if (m.distance < config.threshold || prior->fallback_radius <= r) return m;
  const int window_evaluated = m.evaluated;
  if (2 * prior->fallback_radius + 1 >= sectors) {  // the paper's fall-back: the full search, window included
    m = fullShiftSearch(a, b);
    m.evaluated += window_evaluated;
  } else {  // only the shifts beyond the window on either side (a tie keeps the window's best)
    const int side = prior->fallback_radius - r;
    for (const ShiftMatch& s : {searchShifts(a, b, center + r + 1, side),
                                searchShifts(a, b, center - prior->fallback_radius, side)}) {
      if (s.distance < m.distance) {
        m.distance = s.distance;
        m.shift = s.shift;
        m.yaw = s.yaw;
      }
      m.evaluated += s.evaluated;
    }
    m.narrowed = false;
  }
  m.fell_back = true;
  return m;
}

int sectorKeyShift(const ScanContext& a, const ScanContext& b) {
  requireSameShape(a, b);
  const int sectors = static_cast<int>(a.image.cols());
  int best_shift = 0;
  float best = std::numeric_limits<float>::infinity();
  for (int n = 0; n < sectors; ++n) {
    float l1 = 0;
    for (int j = 0; j < sectors; ++j) l1 += std::abs(a.sector_key(j) - b.sector_key(wrapShift(j - n, sectors)));
    if (l1 < best) {
      best = l1;
      best_shift = n;
    }
  }
  return best_shift;
}

ShiftMatch sectorKeyShiftSearch(const ScanContext& a, const ScanContext& b, const ScanContextConfig& config) {
  requireSameShape(a, b);
  const int sectors = static_cast<int>(a.image.cols());
  const int width = std::min(2 * config.search_radius + 1, sectors);
  ShiftMatch m = searchShifts(a, b, sectorKeyShift(a, b) - config.search_radius, width);
  m.narrowed = true;
  return m;
}

AugmentedMatch augmentedShiftSearch(const ScanContext& a, const AugmentedScanContext& b,
                                    std::optional<YawPrior> yaw_prior, const ScanContextConfig& config) {
  if (b.descriptors.empty() || b.descriptors.size() != b.offsets.size())
    throw std::invalid_argument("augmented scan context has no descriptors or mismatched offsets");
  AugmentedMatch best;
  for (std::size_t i = 0; i < b.descriptors.size(); ++i) {
    const ShiftMatch m = narrowedShiftSearch(a, b.descriptors[i], yaw_prior, config);
    if (i == 0 || m.distance < best.match.distance) {
      best.match = m;
      best.index = static_cast<int>(i);
      best.offset = b.offsets[i];
    }
  }
  return best;
}

Eigen::Isometry3d relativePoseFromMatch(const AugmentedMatch& match, const Eigen::Matrix3d& R_tilt) {
  const double yaw = match.match.yaw;
  const Eigen::Matrix3d R_yaw = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = geometry::withRollPitchOf(R_yaw, R_tilt);
  const Eigen::Vector3d offset(match.offset.x(), match.offset.y(), 0.0);
  T.translation() = -(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * offset);
  return T;
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
