// Course paths: pieces, Dubins connections and the 2-D path index. (Speed profile: scenario_profile.cpp.)
#include "sim/scenario_course.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace drover::sim::detail {
namespace {

constexpr double kPi = std::numbers::pi;

double mod2Pi(double a) {
  a = std::fmod(a, 2.0 * kPi);
  return a < 0.0 ? a + 2.0 * kPi : a;
}

Eigen::Vector2d leftNormal(double heading) { return {-std::sin(heading), std::cos(heading)}; }

}  // namespace

Eigen::Vector2d PlanarPose::forward() const { return {std::cos(heading), std::sin(heading)}; }
Eigen::Vector2d PlanarPose::left() const { return leftNormal(heading); }
Eigen::Vector2d PlanarPose::toWorld(double x, double y) const { return p + x * forward() + y * left(); }

double CoursePiece::grade(double u) const { return grade0 + (grade1 - grade0) * u / length; }

PlanarPose CoursePiece::at(double u) const {
  PlanarPose q;
  q.heading = start.heading + curvature * u;
  if (std::abs(curvature) < 1e-12) {
    q.p = start.p + u * start.forward();
  } else {  // circle of radius 1 / curvature about the centre on the turning side
    const double r = 1.0 / curvature;
    q.p = start.p + r * Eigen::Vector2d(std::sin(q.heading) - std::sin(start.heading),
                                        -std::cos(q.heading) + std::cos(start.heading));
  }
  q.z = start.z + grade0 * u + (grade1 - grade0) * u * u / (2.0 * length);
  return q;
}

Course::Course(const PlanarPose& start) : end_(start) {}

void Course::add(CoursePiece piece) {
  if (!(piece.length > 0.0) || !std::isfinite(piece.length))
    throw std::invalid_argument("Course: piece length must be > 0, got " + std::to_string(piece.length));
  if (!(piece.speed > 0.0))
    throw std::invalid_argument("Course: speed must be > 0, got " + std::to_string(piece.speed));
  piece.start = end_;
  s_start_.push_back(length_);
  length_ += piece.length;
  end_ = piece.at(piece.length);
  pieces_.push_back(piece);
}

void Course::straight(double length, double speed) {
  if (length < 1e-9) return;
  add({length, 0.0, 0.0, 0.0, speed, {}});
}

void Course::arc(double angle, double radius, double speed) {
  if (!(radius > 0.0)) throw std::invalid_argument("Course::arc: radius must be > 0, got " + std::to_string(radius));
  if (std::abs(angle) * radius < 1e-9) return;
  add({std::abs(angle) * radius, (angle > 0.0 ? 1.0 : -1.0) / radius, 0.0, 0.0, speed, {}});
}

void Course::ramp(double run, double grade, double speed) {
  if (!(run > kRampTransition))
    throw std::invalid_argument("Course::ramp: run must exceed the transitions, got " + std::to_string(run));
  add({kRampTransition, 0.0, 0.0, grade, speed, {}});
  add({run - kRampTransition, 0.0, grade, grade, speed, {}});
  add({kRampTransition, 0.0, grade, 0.0, speed, {}});
}

void Course::dubinsTo(const PlanarPose& target, double radius, double speed) {
  struct Candidate {
    double a0, straight, a1;  // signed turn angles [rad] and straight length [m]
  };
  double best = std::numeric_limits<double>::infinity();
  Candidate chosen{0, 0, 0};
  for (const int s0 : {1, -1}) {    // +1: left circle at the start
    for (const int s1 : {1, -1}) {  // at the target
      const Eigen::Vector2d c0 = end_.p + s0 * radius * end_.left();
      const Eigen::Vector2d c1 = target.p + s1 * radius * target.left();
      const Eigen::Vector2d d = c1 - c0;
      const double dist = d.norm(), psi = std::atan2(d.y(), d.x());
      double theta = psi, straight = dist;
      if (s0 != s1) {  // inner tangent: D = L u -/+ 2 r n(u)
        if (dist < 2.0 * radius) continue;
        straight = std::sqrt(dist * dist - 4.0 * radius * radius);
        theta = psi + s0 * std::atan2(2.0 * radius, straight);
      }
      const double a0 = s0 > 0 ? mod2Pi(theta - end_.heading) : -mod2Pi(end_.heading - theta);
      const double a1 = s1 > 0 ? mod2Pi(target.heading - theta) : -mod2Pi(theta - target.heading);
      const double total = radius * (std::abs(a0) + std::abs(a1)) + straight;
      if (total < best) best = total, chosen = {a0, straight, a1};
    }
  }
  arc(chosen.a0, radius, speed);
  straight(chosen.straight, speed);
  arc(chosen.a1, radius, speed);
}

void Course::open(Condition c) {
  labels_.push_back({c, length_, length_});
  open_.push_back(true);
}

void Course::close(Condition c) {
  for (std::size_t i = labels_.size(); i-- > 0;) {
    if (labels_[i].condition == c && open_[i]) {
      labels_[i].s1 = length_;
      open_[i] = false;
      return;
    }
  }
  throw std::logic_error("Course::close: no open label " + conditionName(c));
}

std::size_t Course::pieceAt(double s) const {
  if (pieces_.empty()) throw std::logic_error("Course: empty");
  const auto it = std::upper_bound(s_start_.begin(), s_start_.end(), s);
  return it == s_start_.begin() ? 0 : static_cast<std::size_t>(it - s_start_.begin()) - 1;
}

PlanarPose Course::poseAt(double s) const {
  s = std::clamp(s, 0.0, length_);
  const std::size_t i = pieceAt(s);
  return pieces_[i].at(std::min(s - s_start_[i], pieces_[i].length));
}

double Course::gradeAt(double s) const {
  s = std::clamp(s, 0.0, length_);
  const std::size_t i = pieceAt(s);
  return pieces_[i].grade(std::min(s - s_start_[i], pieces_[i].length));
}

double Course::curvatureAt(double s) const { return pieces_[pieceAt(std::clamp(s, 0.0, length_))].curvature; }
double Course::speedAt(double s) const { return pieces_[pieceAt(std::clamp(s, 0.0, length_))].speed; }

std::vector<Eigen::Vector2d> Course::polyline(double spacing) const {
  std::vector<Eigen::Vector2d> pts;
  const int n = std::max(1, static_cast<int>(std::ceil(length_ / spacing)));
  for (int i = 0; i <= n; ++i) pts.push_back(poseAt(length_ * i / n).p);
  return pts;
}

// ---- clearance queries --------------------------------------------------------------------------------------

double distanceToFootprint(const Footprint& f, const Eigen::Vector2d& q) {
  const Eigen::Vector2d d = q - f.center;
  const double c = std::cos(f.yaw), s = std::sin(f.yaw);
  const Eigen::Vector2d local(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  const Eigen::Vector2d outside = (local.cwiseAbs() - f.half).cwiseMax(0.0);
  return std::max(0.0, outside.norm() - f.radius);
}

bool footprintsOverlap(const Footprint& a, const Footprint& b) {
  // Separating-axis test on the two rectangles' axes (a circle's radius pads its extent on every axis).
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)},
                                   {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)},
                                   {-std::sin(b.yaw), std::cos(b.yaw)}};
  const auto extent = [&](const Footprint& f, const Eigen::Vector2d& n, int first) {
    return f.half.x() * std::abs(axes[first].dot(n)) + f.half.y() * std::abs(axes[first + 1].dot(n)) + f.radius;
  };
  for (const Eigen::Vector2d& n : axes) {
    if (std::abs((b.center - a.center).dot(n)) > extent(a, n, 0) + extent(b, n, 2)) return false;
  }
  return true;
}

PathIndex::PathIndex(std::vector<Eigen::Vector2d> points, double cell) : points_(std::move(points)), cell_(cell) {
  if (!(cell > 0.0)) throw std::invalid_argument("PathIndex: cell must be > 0, got " + std::to_string(cell));
  for (std::uint32_t i = 0; i < points_.size(); ++i) {
    const auto ix = static_cast<std::int64_t>(std::floor(points_[i].x() / cell_));
    const auto iy = static_cast<std::int64_t>(std::floor(points_[i].y() / cell_));
    grid_[key(ix, iy)].push_back(i);
  }
}

double PathIndex::distance(const Footprint& f, double limit) const {
  const double reach = f.half.norm() + f.radius + limit;
  const auto x0 = static_cast<std::int64_t>(std::floor((f.center.x() - reach) / cell_));
  const auto x1 = static_cast<std::int64_t>(std::floor((f.center.x() + reach) / cell_));
  const auto y0 = static_cast<std::int64_t>(std::floor((f.center.y() - reach) / cell_));
  const auto y1 = static_cast<std::int64_t>(std::floor((f.center.y() + reach) / cell_));
  double best = limit;
  for (std::int64_t ix = x0; ix <= x1; ++ix) {
    for (std::int64_t iy = y0; iy <= y1; ++iy) {
      const auto it = grid_.find(key(ix, iy));
      if (it == grid_.end()) continue;
      for (const std::uint32_t i : it->second) best = std::min(best, distanceToFootprint(f, points_[i]));
    }
  }
  return best;
}

}  // namespace drover::sim::detail
