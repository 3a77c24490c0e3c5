#pragma once
// Internal to the scenarios (not part of the simulator's interface): a course path built from pieces (straights,
// arcs, ramps with smooth vertical transitions, Dubins connections), its speed profile (rest at both ends,
// bounded speed, acceleration and lateral acceleration) and its sampling into PathSamples; and a 2-D index of path
// points for clearance queries when placing the world around the path. World frame: z up [m]; headings [rad]
// counter-clockwise from +x, unwrapped.
#include <Eigen/Core>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "sim/scenario.hpp"
#include "sim/trajectory.hpp"

namespace drover::sim::detail {

// A pose on the course: planar position, heading and the height of the surface driven on.
struct PlanarPose {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();  // [m]
  double heading = 0;                           // [rad], unwrapped
  double z = 0;                                 // [m] surface height (the body is kBodyHeight above it)
  // A point given in this pose's frame (x forward, y left) in the world plane.
  Eigen::Vector2d toWorld(double x, double y) const;
  Eigen::Vector2d forward() const;
  Eigen::Vector2d left() const;
};

// One piece: constant curvature in the plane; grade (dz/ds) linear in s from grade0 to grade1.
struct CoursePiece {
  double length = 0;     // [m], horizontal
  double curvature = 0;  // [1/m], > 0 turns left
  double grade0 = 0, grade1 = 0;
  double speed = 1.0;  // [m/s] speed limit on the piece
  PlanarPose start;
  PlanarPose at(double u) const;  // u in [0, length]
  double grade(double u) const;
};

struct CourseLabel {
  Condition condition;
  double s0 = 0, s1 = 0;  // [m] arc-length span
};

class Course {
 public:
  static constexpr double kRampTransition = 2.0;  // [m] vertical curve at each end of a ramp

  explicit Course(const PlanarPose& start = {});
  const PlanarPose& end() const { return end_; }
  double length() const { return length_; }

  void straight(double length, double speed);
  void arc(double angle, double radius, double speed);  // angle [rad] > 0: left turn
  // A ramp of horizontal run `run` and grade `grade` (< 0 down). The ideal planar ramp starts kRampTransition / 2
  // after the current end; the path rounds both kinks over kRampTransition and ends kRampTransition / 2 past the
  // ramp's far end, having risen grade * run.
  void ramp(double run, double grade, double speed);
  // Shortest of the Dubins curve-straight-curve paths (LSL, RSR, LSR, RSL) of turn radius `radius` to `target`.
  void dubinsTo(const PlanarPose& target, double radius, double speed);

  void open(Condition c);   // opens a label at the current end
  void close(Condition c);  // closes the latest open label of c

  PlanarPose poseAt(double s) const;
  double gradeAt(double s) const;
  double curvatureAt(double s) const;
  double speedAt(double s) const;
  const std::vector<CourseLabel>& labels() const { return labels_; }
  // Points along the course every `spacing` m (for clearance queries).
  std::vector<Eigen::Vector2d> polyline(double spacing) const;

 private:
  void add(CoursePiece piece);
  std::size_t pieceAt(double s) const;
  std::vector<CoursePiece> pieces_;
  std::vector<double> s_start_;
  std::vector<CourseLabel> labels_;
  std::vector<bool> open_;
  PlanarPose end_;
  double length_ = 0;
};

struct ProfileOptions {
  double max_accel = 0.4;           // [m/s^2] along the path
  double max_lateral = 0.3;         // [m/s^2] in turns
  double hold_start_s = 2.0;        // [s] at rest before moving (static IMU initialisation)
  double hold_end_s = 2.0;          // [s] at rest at the end
  Time knot_spacing = 100'000'000;  // [ns]
  double body_height = CourseGeometry::kBodyHeight;
};

struct TimedCourse {
  std::vector<PathSample> samples;  // every knot_spacing from t = 0 to the end (inclusive)
  std::vector<Segment> segments;    // the course's labels in time
  double max_speed = 0;             // [m/s] of the profile
};

// Time-optimal profile under the limits (forward/backward passes on a 1 cm grid, constant acceleration between
// grid points), then sampled. Starts and ends at rest.
TimedCourse timeCourse(const Course& course, const ProfileOptions& options);

// 2-D grid of path points for "how far is the nearest part of the path" queries.
struct Footprint {
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  Eigen::Vector2d half = Eigen::Vector2d::Zero();  // oriented rectangle half extents [m]; zero: a point/circle
  double yaw = 0;
  double radius = 0;  // added all round (circles: half = 0, radius > 0)
};

class PathIndex {
 public:
  PathIndex(std::vector<Eigen::Vector2d> points, double cell = 4.0);
  // Smallest distance from the footprint to any path point, or `limit` when none is nearer than limit.
  double distance(const Footprint& f, double limit) const;

 private:
  std::int64_t key(std::int64_t ix, std::int64_t iy) const { return ix * 1'000'003LL + iy; }
  std::vector<Eigen::Vector2d> points_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> grid_;
};

double distanceToFootprint(const Footprint& f, const Eigen::Vector2d& q);
bool footprintsOverlap(const Footprint& a, const Footprint& b);

}  // namespace drover::sim::detail
