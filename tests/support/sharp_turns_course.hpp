#pragma once
// The start of the simulated sharp-turns course for lidar-inertial tests: at rest for 2.5 s, an 11 m straight, then
// turning at ~19 deg/s from 13.5 s; VLP-16 and IMU (simulator seed 7), no camera. Built on the live system's course
// helpers (live_course.hpp), with a start in motion (measurements before from_s dropped) and a truth lookup.
#include <algorithm>

#include "support/live_course.hpp"

namespace drover::test {

// The course's first duration_s seconds; the measurements before from_s [s] are dropped (a start in motion).
inline LiveCourse sharpTurnsCourse(double duration_s, double from_s = 0.0) {
  LiveCourse c = simulateLiveCourse("sharp-turns", duration_s, 7);
  c.stream.erase(std::remove_if(c.stream.begin(), c.stream.end(),
                                [&](const Measurement& m) { return measurementTime(m) < fromSeconds(from_s); }),
                 c.stream.end());
  return c;
}

// Iterator to the first truth sample at or after t (end() when none).
inline Trajectory::const_iterator truthFrom(const Trajectory& truth, Time t) {
  return std::lower_bound(truth.begin(), truth.end(), t, [](const StampedPose& p, Time x) { return p.t < x; });
}

}  // namespace drover::test
