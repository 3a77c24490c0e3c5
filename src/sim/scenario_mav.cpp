// mav-room: a micro aerial vehicle flying in a textured indoor room, the motion class of EuRoC's Vicon-room
// sequences (Burri et al., IJRR 2016), for the VIS alone on the rig of SimulatorConfig::eurocRig(). Not a ground
// course: the body flies in 6 DoF, so no condition label, no ground height.
//
// EuRoC V1_01_easy flies 58.6 m in 143.6 s (0.41 m/s mean, up to ~0.9 m/s) at ~0.3 rad/s mean angular rate,
// V1_02_medium 0.91 m/s and ~0.6 rad/s. Here: 100 s, hovering still for 2 s at each end (static IMU
// initialisation), the motion faded in and out over 3 s; in between sums of sinusoids at incommensurate periods
// (so no pose repeats exactly): position within +-2.4 m x +-2.1 m x +-0.6 m of the room's centre (1.5 m up), the
// body yawing over +-112 deg to look at every wall, pitched 2-15 deg down (EuRoC's camera looks down too), rolling
// +-6 deg. Measured (tests/sim/test_scenario_mav.cpp): 0.74 m/s mean and 1.32 m/s peak speed, 0.30 rad/s mean and
// 0.65 rad/s peak angular rate, up to 1.0 m/s^2 of acceleration, 72 m: between V1_01 and V1_02.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <numbers>

#include "sim/scenario_internal.hpp"

namespace drover::sim::detail {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kHalfX = 5.0, kHalfY = 4.0, kHeight = 4.0;  // [m] the room: [-5, 5] x [-4, 4] x [0, 4]
constexpr double kHover = 1.5;                                // [m] height of the room's centre of flight
constexpr double kDuration = 100.0, kRest = 2.0, kFade = 3.0;  // [s]

// 0 before `from`, 1 after `from + width`, the quintic smoothstep between (C2, so the spline's acceleration and
// the IMU stay smooth where the motion fades in).
double fade(double t, double from, double width) {
  const double x = std::clamp((t - from) / width, 0.0, 1.0);
  return x * x * x * (x * (6 * x - 15) + 10);
}

// Amplitude [m or rad], period [s], phase [rad].
struct Wave {
  double amplitude, period, phase;
};

double waves(double t, std::initializer_list<Wave> terms) {
  double sum = 0;
  for (const Wave& w : terms) sum += w.amplitude * std::sin(2 * kPi * t / w.period + w.phase);
  return sum;
}

PathSample flightAt(double t) {
  const double e = fade(t, kRest, kFade) * (1.0 - fade(t, kDuration - kRest - kFade, kFade));
  PathSample s;
  s.t = fromSeconds(t);
  s.p_world = Eigen::Vector3d(e * waves(t, {{2.0, 23, 0}, {0.4, 5.3, 1.0}}),
                              e * waves(t, {{1.7, 17, 0.5}, {0.4, 6.1, 2.0}}),
                              kHover + e * waves(t, {{0.45, 11, 0}, {0.15, 3.7, 1.3}}));
  s.yaw = e * waves(t, {{1.6, 29, 0}, {0.35, 7.3, 0.7}});
  s.pitch = 0.15 + e * waves(t, {{0.12, 6.7, 0}});  // positive pitch of a z-up, x-forward body looks down
  s.roll = e * waves(t, {{0.1, 4.9, 0.4}});
  return s;
}

std::vector<PathSample> flight() {
  std::vector<PathSample> samples;
  for (int k = 0; k <= static_cast<int>(std::lround(kDuration * 10)); ++k) samples.push_back(flightAt(0.1 * k));
  return samples;
}

// Walls, floor and ceiling, each with its own texture, posters on the walls and a few objects on the floor: a
// Vicon room's clutter. Walls, boxes and the pillar stand at least 1.5 m outside the flight's volume, the floor and
// its mats 0.9 m below its lowest point, the ceiling 1.9 m above its highest.
void buildRoom(std::uint64_t seed, WorldBuilder& w) {
  const auto s = [seed](std::uint32_t k) { return static_cast<std::uint32_t>(seed * 97 + k); };
  w.ground(0.0, makeMaterial(Texture::kConcrete, {0.45f, 0.45f, 0.43f}, 0.5f, 0.4f, s(1)));
  const Eigen::Vector2d c[4] = {{-kHalfX, -kHalfY}, {kHalfX, -kHalfY}, {kHalfX, kHalfY}, {-kHalfX, kHalfY}};
  // Textures with detail at several scales. Fine periodic ones alias into moire at a few metres (bricks of 2.6 cm
  // tracked 30 of ~110 features at 4 m in a first version; pens and fences likewise): a Vicon room's posters, cables
  // and curtains are not periodic. Blocks of 15 x 45 cm and concrete mottled at 12 cm instead.
  const Material walls[4] = {makeMaterial(Texture::kBrick, {0.55f, 0.3f, 0.22f}, 0.5f, 2.0f, s(2)),
                             makeMaterial(Texture::kConcrete, {0.6f, 0.6f, 0.58f}, 0.5f, 1.0f, s(3)),
                             makeMaterial(Texture::kNoise, {0.5f, 0.55f, 0.6f}, 0.5f, 0.15f, s(4)),
                             makeMaterial(Texture::kBark, {0.45f, 0.4f, 0.35f}, 0.4f, 0.3f, s(5))};
  for (int i = 0; i < 4; ++i) w.structure(verticalRect(c[i], c[(i + 1) % 4], 0.0, kHeight), walls[i]);
  Rectangle ceiling;
  ceiling.T_world_rect.translation() = Eigen::Vector3d(0, 0, kHeight);
  ceiling.half_size = Eigen::Vector2d(kHalfX, kHalfY);
  w.structure(ceiling, makeMaterial(Texture::kConcrete, {0.7f, 0.7f, 0.7f}, 0.5f, 0.8f, s(6)));
  // Posters 2 cm in front of each wall (inward), two a wall, fine noise texture of differing scale.
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector2d a = c[i], b = c[(i + 1) % 4], along = (b - a).normalized();
    const Eigen::Vector2d inward = Eigen::Vector2d(-along.y(), along.x()) * 0.02;
    for (int j = 0; j < 2; ++j) {
      const double at = (j == 0 ? 0.3 : 0.65) * (b - a).norm(), width = 1.2 + 0.3 * ((seed + i + j) % 3);
      const double z0 = 0.8 + 0.3 * ((seed + 2 * i + j) % 2);
      const Material poster =
          makeMaterial(Texture::kNoise, {0.3f + 0.2f * j, 0.35f, 0.4f}, 0.5f, 0.05f + 0.04f * j, s(10 + 2 * i + j));
      w.structure(verticalRect(a + along * at + inward, a + along * (at + width) + inward, z0, z0 + 1.0), poster);
    }
  }
  // Mats on the floor and objects along the walls.
  for (int j = 0; j < 3; ++j) {
    Rectangle mat;
    mat.T_world_rect.translation() = Eigen::Vector3d(-2.0 + 2.0 * j, 0.5 * j - 0.5, 0.01);
    mat.half_size = Eigen::Vector2d(0.9, 0.6);
    w.structure(mat, makeMaterial(Texture::kNoise, {0.15f, 0.15f, 0.17f}, 0.2f, 0.1f, s(20 + j)));
  }
  w.structure(yawBox({4.3, -3.2, 0}, {0.4, 0.5, 0.45}, 0.3),
              makeMaterial(Texture::kStraw, {0.8f, 0.7f, 0.4f}, 0.45f, 0.08f, s(30)));
  w.structure(yawBox({-4.2, 3.0, 0}, {0.5, 0.4, 0.6}, -0.2),
              makeMaterial(Texture::kMetal, {0.6f, 0.62f, 0.65f}, 0.6f, 1.0f, s(31)));
  w.structure(yawBox({4.2, 3.1, 0}, {0.5, 0.6, 0.35}, 0.0),
              makeMaterial(Texture::kBrick, {0.6f, 0.35f, 0.25f}, 0.5f, 1.0f, s(32)));
  Cylinder pillar;
  pillar.base_center = Eigen::Vector3d(-4.0, -3.0, 0.0);
  pillar.radius = 0.3;
  pillar.height = kHeight;
  w.structure(pillar, makeMaterial(Texture::kBark, {0.4f, 0.35f, 0.3f}, 0.4f, 0.2f, s(33)));
  w.indoor({Eigen::Vector3d(-kHalfX, -kHalfY, -1.0), Eigen::Vector3d(kHalfX, kHalfY, kHeight + 1.0)});
}

}  // namespace

Scenario makeMavRoom(const ScenarioOptions& options) {
  ScenarioParts parts;
  parts.name = "mav-room";
  parts.samples = flight();
  WorldBuilder room;
  buildRoom(options.seed, room);
  parts.lighting.indoor_regions = room.indoorRegions();
  parts.world = room.finish(PathIndex({}));  // every object is placed by design: no decoration to keep clear
  return finishScenario(std::move(parts), options);
}

}  // namespace drover::sim::detail
