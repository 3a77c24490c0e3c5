#pragma once
// Scenarios: a world, the robot's path through it, the lighting, and labelled time spans saying which condition
// of the livestock-farm course each part exercises. Scenario building does no file IO: kitti05-replay receives
// the KITTI 05 ground truth from the caller.
#include <memory>
#include <string>
#include <vector>

#include "sim/camera_model.hpp"
#include "sim/trajectory.hpp"
#include "sim/world.hpp"
#include "types/trajectory.hpp"

namespace drover::sim {

// The eight course conditions and three degradations.
enum class Condition {
  kUphill, kDownhill, kGarageExit, kGarageEntry, kJolting, kStraight, kOverlap, kSharpTurns,  // course
  kWhiteWalls, kCorridor, kLighting                                                            // degradations
};
std::string conditionName(Condition c);  // "uphill", "downhill", "garage-exit", ..., "white-walls", "corridor", "lighting"

struct Segment {
  Condition condition;
  Time start = 0, end = 0;  // [ns]
};

struct Scenario {
  std::string name;
  World world;                                   // built (World::build() called)
  std::shared_ptr<const SplineTrajectory> trajectory;
  Illumination illumination;                     // never empty
  std::vector<Segment> segments;                 // labelled spans, in time order (they may overlap)
  bool closes_loop = false;                      // ends where it started / revisits a place
  double max_speed = 0;                          // [m/s], max |v| of the trajectory sampled at 10 Hz
};

struct ScenarioOptions {
  std::uint64_t seed = 1;  // varies the decoration (trees, bales, facades); never the path
  // 0: the scenario's natural length. Shorter: the path is cut, the trajectory spans [0, duration] (it then ends
  // moving). Longer: courses that close their loop (farm, overlap) are driven again lap after lap (each lap starts
  // and ends at rest at the same pose, yaw continues unwrapped), then cut; open courses stay at rest at their end
  // pose for the remaining time; kitti05-replay, which ends moving, throws std::invalid_argument. Segments are cut
  // or repeated with the path.
  double duration_s = 0;
  const Trajectory* kitti05_ground_truth = nullptr;  // lidar/camera-0 poses of KITTI 05 with times (kitti05-replay)
};

// Names: uphill, downhill, garage-exit, garage-entry, jolting, straight, overlap, sharp-turns (each condition
// alone), white-walls, corridor, lighting (each degradation alone), farm (the ~600 m closed course through all of
// them at 0..1.2 m/s), kitti05-replay and mav-room (a micro aerial vehicle flying 100 s in a textured room, EuRoC's
// Vicon-room class of motion, for the rig of SimulatorConfig::eurocRig(); scenario_mav.cpp). Throws std::invalid_argument for an unknown name (listing the known ones)
// or kitti05-replay without ground truth.
//
// Course scenarios (farm and the single conditions): the path is built from straights, arcs and ramps (10 % grade,
// 2 m vertical transitions), timed by a speed profile that starts and ends at rest (2 s still at each end, for
// static IMU initialisation) with |a| <= 0.4 m/s^2 along the path and <= 0.3 m/s^2 across it, and sampled every
// 0.1 s (yaw = heading unwrapped, pitch = -atan(grade), roll = 0). Body height kBodyHeight above the surface.
// Jolting adds vibrations (z 1.5 cm at 2.5 Hz + 0.4 cm at 6.1 Hz, pitch 1.5 + 0.5 deg at 1.8 / 4.4 Hz, roll 2 +
// 0.6 deg at 1.3 / 3.7 Hz). Lighting: outdoor 1, indoor 0.5, and over each "lighting" span a geometric ramp down
// to a night level of 5e-4, a dark stretch, a ramp back and 4 Hz flicker of depth 0.3. "overlap" segments are found, not declared:
// wherever the path comes within 2 m of where it was >= 30 s before.
// Approximations: sharp turns are tight arcs (r = 1.5 m at 0.5 m/s), not turns on the spot; a ramp's surface is
// planar, so over its 2 m vertical transitions the body is up to ~3 cm off kBodyHeight; fences and pens are flat
// rectangles (textured, no posts); indoor regions are axis-aligned boxes.
// kitti05-replay: kittiCameraToZupBody(ground truth), Hermite-interpolated (position and Z-Y-X angles) onto the
// 0.1 s grid and interpolated by the spline; trajectory time = ground-truth time - first ground-truth time. The
// ground truth's own jitter gives acceleration spikes (p99 ~5 m/s^2, max ~15 m/s^2). The body is camera 0; the road
// lies kKittiCameraHeight below it (asphalt strips following the path; the ground plane below the lowest point).
Scenario makeScenario(const std::string& name, const ScenarioOptions& options);
std::vector<std::string> scenarioNames();

// Geometry the course scenarios promise (tests check against these).
struct CourseGeometry {
  static constexpr double kBodyHeight = 0.4;          // [m] body (IMU) origin above the surface driven on
  static constexpr double kRampGrade = 0.10;          // rise / run of the ramps (10 %)
  static constexpr double kRampRun = 15.0;            // [m] horizontal run of one ramp: rise = grade * run
  static constexpr double kCorridorHalfWidth = 2.5;   // [m] path centre line to the corridor's wall faces
  static constexpr double kCorridorLength = 50.0;     // [m]
  static constexpr double kWhiteHalfWidth = 2.5;      // [m] path to the white walls
  static constexpr double kClearance = 1.5;           // [m] no wall, fence or decoration nearer to the path
  static constexpr double kFarmMaxSpeed = 1.2;        // [m/s]
  static constexpr double kKittiCameraHeight = 1.65;  // [m] KITTI camera 0 above the road
  static constexpr double kTownClearance = 2.0;       // [m] no town primitive (but the road) nearer to the path
};

// KITTI camera-0 poses (x right, y down, z forward; world = first camera frame) to T_world_body of a z-up body
// (x forward, y left, z up) in a z-up world: T_world_body = L * A * T_cam0world_cam * A^T, with A the fixed axis
// permutation camera -> body and L the rotation that levels the plane fitted to the positions (KITTI's first
// camera frame is about 2 deg off gravity; levelled, the 2.2 km of sequence 05 stay within 3 m of height). Times are kept. kitti05-replay drives exactly this trajectory.
Trajectory kittiCameraToZupBody(const Trajectory& camera_poses);

}  // namespace drover::sim
