// Speed profile of a course and its sampling into PathSamples.
//
// The profile is the classic time-optimal one under a speed limit v_max(s) and an acceleration bound a:
// v(s) = min(v_max(s), forward pass sqrt(v(s - ds)^2 + 2 a ds), backward pass likewise), with v = 0 at both ends;
// between grid points the acceleration is constant, so t and s(t) follow in closed form.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "sim/scenario_course.hpp"

namespace drover::sim::detail {
namespace {

constexpr double kGridStep = 0.01;  // [m] profile grid

struct Profile {
  double ds = 0;
  std::vector<double> v;  // [m/s] horizontal speed at s = i ds
  std::vector<double> t;  // [s] time at s = i ds (t[0] = hold_start_s)
};

// Limit on the horizontal speed at s: the piece's limit on the 3-D speed, and the lateral acceleration in turns.
double speedLimit(const Course& course, double s, const ProfileOptions& o) {
  double v = course.speedAt(s);
  const double k = std::abs(course.curvatureAt(s));
  if (k > 0.0) v = std::min(v, std::sqrt(o.max_lateral / k));
  const double g = course.gradeAt(s);
  return v / std::sqrt(1.0 + g * g);
}

Profile makeProfile(const Course& course, const ProfileOptions& o) {
  Profile p;
  const auto n = static_cast<std::size_t>(std::max(2.0, std::ceil(course.length() / kGridStep)));
  p.ds = course.length() / static_cast<double>(n);
  p.v.resize(n + 1);
  for (std::size_t i = 0; i <= n; ++i) p.v[i] = speedLimit(course, p.ds * static_cast<double>(i), o);
  p.v.front() = p.v.back() = 0.0;
  const double two_a_ds = 2.0 * o.max_accel * p.ds;
  for (std::size_t i = 0; i < n; ++i) p.v[i + 1] = std::min(p.v[i + 1], std::sqrt(p.v[i] * p.v[i] + two_a_ds));
  for (std::size_t i = n; i > 0; --i) p.v[i - 1] = std::min(p.v[i - 1], std::sqrt(p.v[i] * p.v[i] + two_a_ds));
  p.t.resize(n + 1);
  p.t[0] = o.hold_start_s;
  for (std::size_t i = 0; i < n; ++i) {
    const double vsum = p.v[i] + p.v[i + 1];
    if (!(vsum > 0.0)) throw std::logic_error("speed profile: zero speed inside the course");
    p.t[i + 1] = p.t[i] + 2.0 * p.ds / vsum;
  }
  return p;
}

// Arc length at time t [s].
double arcLengthAt(const Profile& p, double t) {
  if (t <= p.t.front()) return 0.0;
  if (t >= p.t.back()) return p.ds * static_cast<double>(p.t.size() - 1);
  const auto i = static_cast<std::size_t>(std::upper_bound(p.t.begin(), p.t.end(), t) - p.t.begin()) - 1;
  const double tau = t - p.t[i];
  const double a = (p.v[i + 1] * p.v[i + 1] - p.v[i] * p.v[i]) / (2.0 * p.ds);
  const double ds = std::clamp(p.v[i] * tau + 0.5 * a * tau * tau, 0.0, p.ds);
  return p.ds * static_cast<double>(i) + ds;
}

// Time [s] at arc length s; labels at the very start or end include the rest there.
double timeAt(const Profile& p, double s, double end_time) {
  const double total = p.ds * static_cast<double>(p.t.size() - 1);
  if (s <= 1e-9) return 0.0;
  if (s >= total - 1e-9) return end_time;
  const double x = s / p.ds;
  const auto i = std::min(static_cast<std::size_t>(x), p.t.size() - 2);
  return p.t[i] + (x - static_cast<double>(i)) * (p.t[i + 1] - p.t[i]);
}

}  // namespace

TimedCourse timeCourse(const Course& course, const ProfileOptions& o) {
  if (!(course.length() > 0.0)) throw std::invalid_argument("timeCourse: empty course");
  if (o.knot_spacing <= 0)
    throw std::invalid_argument("timeCourse: knot_spacing must be > 0, got " + std::to_string(o.knot_spacing));
  const Profile p = makeProfile(course, o);
  const double end_time = p.t.back() + o.hold_end_s;
  const double dt = toSeconds(o.knot_spacing);
  const auto count = static_cast<std::int64_t>(std::ceil(end_time / dt - 1e-9));

  TimedCourse out;
  out.samples.reserve(static_cast<std::size_t>(count + 1));
  for (std::int64_t k = 0; k <= count; ++k) {
    const double s = arcLengthAt(p, static_cast<double>(k) * dt);
    const PlanarPose q = course.poseAt(s);
    PathSample sample;
    sample.t = k * o.knot_spacing;
    sample.p_world = Eigen::Vector3d(q.p.x(), q.p.y(), q.z + o.body_height);
    sample.yaw = q.heading;
    // Z-Y-X Euler angles: R = Rz(yaw) Ry(pitch) Rx(roll); body x = (cos p cos y, cos p sin y, -sin p), so the
    // nose points up a slope of grade g for pitch = -atan(g).
    sample.pitch = -std::atan(course.gradeAt(s));
    out.samples.push_back(sample);
  }
  const double sample_end = static_cast<double>(count) * dt;
  for (const CourseLabel& l : course.labels()) {
    Segment seg{l.condition, fromSeconds(timeAt(p, l.s0, sample_end)), fromSeconds(timeAt(p, l.s1, sample_end))};
    out.segments.push_back(seg);
  }
  std::stable_sort(out.segments.begin(), out.segments.end(),
                   [](const Segment& a, const Segment& b) { return a.start < b.start; });
  for (std::size_t i = 0; i < p.v.size(); ++i) {
    const double g = course.gradeAt(p.ds * static_cast<double>(i));
    out.max_speed = std::max(out.max_speed, p.v[i] * std::sqrt(1.0 + g * g));
  }
  return out;
}

}  // namespace drover::sim::detail
