#include "apps/drover/run_preset.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace drover::cli {

std::vector<std::string> presetNames() { return {"drover", "lvi-sam"}; }

Preset presetFromName(const std::string& name) {
  if (name.empty()) return Preset::kPlatform;
  if (name == "drover") return Preset::kDrover;
  if (name == "lvi-sam") return Preset::kLviSam;
  throw std::invalid_argument("--preset: unknown preset '" + name + "' (expected drover or lvi-sam)");
}

const char* presetName(Preset preset) {
  switch (preset) {
    case Preset::kDrover: return "drover";
    case Preset::kLviSam: return "lvi-sam";
    case Preset::kPlatform: break;
  }
  return "platform";
}

namespace {

// LVI-SAM's updateInitialGuess takes the VINS odometry whenever its reset ID matches: no gates, no reset.
void withoutGates(pipeline::VisualMotionConfig& f) {
  constexpr double kNever = std::numeric_limits<double>::max();
  f.max_keyframe_gap = f.max_velocity_difference = f.max_position_difference = f.max_acceleration_difference = kNever;
  f.max_velocity_difference_ratio = f.max_velocity_difference_growth = 0;
  f.reset_after = 0;
  f.min_features = 1;
}

// The drover preset's LK threshold for SuperPoint's tracks (visual::FeatureTrackerConfig::min_eigenvalue: OpenCV's
// units, g^2 / 1024 for an RMS gradient of g grey levels a pixel in the window's weakest direction). Shi-Tomasi picks
// its corners by that eigenvalue (at least 1 % of the frame's strongest corner: ~1e-3 on textured frames), SuperPoint
// by a learnt score that at a low confidence also fires on plain walls and their edges. 2e-3 is ~2x the eigenvalue
// that the simulated camera's shot noise alone gives at mid-grey (~2 grey levels: ~9e-4): it keeps textured tracks
// (its p10 5.5e-3) and drops the plain walls' (in the textureless stretch 75 % of the tracks see only noise and
// fall below it; the walls' edges there are strong enough to stay). On the simulated farm, the whole preset: seeds
// 1 / 2 / 3 0.168 / 0.210 / 0.191 -> 0.130 / 0.123 / 0.190 m, and the VIS re-initialised after a textureless stretch
// no longer tilts itself (bench/RESULTS.md).
// Shi-Tomasi's tracks keep the platform's value: at 2e-3 the farm with Shi-Tomasi went 0.167 -> 0.182 m.
constexpr double kSuperPointMinEigenvalue = 2e-3;

// The drover preset's vio.max_keyframe_interval_s where the platform sets none: a window without parallax (far
// features only, the white walls) still takes a keyframe every ~0.5 s, so that the newest frame never hangs off a
// keyframe by a preintegration of tens of seconds (vio/vio_config.hpp). A moving VIS makes 7-10 keyframes a second
// by parallax, so this acts only where it stalls; the LIS's stall gate counts parallax keyframes alone.
constexpr double kKeyframeInterval = 0.5;  // [s]

// The drover preset's vis_fusion.keyframe_gap_velocity_tolerance: a VIS that made no keyframe by parallax is a stall
// only when its velocity is also this (+ 5 % of the speed) off the IMU's prediction, the band of the velocity gate
// right after the lidar measured the LIS. Driving at far walls a VIS with lidar depth keeps the right speed without
// parallax: farm seed 1 0.156 -> 0.108 m (Shi-Tomasi 0.370 -> 0.106 m), corridor seeds 1-3 0.146 / 0.106 / 0.144 ->
// 0.113 / 0.111 / 0.119 m, seeds 2-3 and the other courses the same. It relies on the preset's VIS failing, not
// coasting, where it sees nothing (visual_motion.hpp): the corridor's textureless fault 0.68 -> 0.71 % drift with the
// preset, 0.78 -> 2.60 % with the platform file's tracks (bench/RESULTS.md).
constexpr double kKeyframeGapVelocityTolerance = 0.2;  // [m/s]

// The drover preset's odometry.lidar_sigma_rotation where the platform file is looser: the scan match's attitude
// enters the IMU smoother at 0.01 rad (0.57 deg) instead of LIO-SAM's 0.05 rad (2.9 deg), a weight at which the
// smoother's pitch rides on the accelerometer bias (g x 0.1 deg = 0.017 m/s^2, inside the bias prior) and the map
// hardly holds it. Along a lidar-degenerate corridor the VO factor measures the velocity that tilt and bias would
// otherwise trade through, and the match's pitch then holds: the corridor's pitch error at its end 0.153 -> 0.048 deg
// (seed 2), height 0.154 -> 0.098 m. A degenerate sweep that nothing aids keeps the platform's sigma
// (lidar_sigma_rotation_unaided): there only the IMU carries the axis, and held to a map built on its own pitch the
// preset (its VIS refused throughout) lost the white walls' seed 1 (0.195 -> 0.262 m). The drover preset, APE rmse,
// 0.05 -> 0.01 with the unaided sweeps at 0.05: corridor seeds 1-3 0.102 / 0.139 / 0.120 -> 0.086 / 0.106 / 0.124 m,
// white walls 0.195 / 0.043 / 0.065 -> 0.169 / 0.043 / 0.062 m, lighting 0.067 -> 0.046 m, farm with loops 0.109 /
// 0.103 / 0.169 -> 0.105 / 0.094 / 0.111 m. Without loops the farm lost on seeds 1 and 2 (0.18 / 0.26 / 0.17 ->
// 0.35 / 0.37 / 0.11 %): back from the white walls' blind stretch the tight weight holds a map built on the tilt
// that stretch drifted to. 0.005 and 0.02 everywhere were worse on the corridor than 0.01 (bench/RESULTS.md).
constexpr double kLidarSigmaRotation = 0.01;  // [rad]

}  // namespace

void applyPreset(Preset preset, pipeline::OdometryConfig& odometry) {
  pipeline::VisualMotionConfig& f = odometry.vis_fusion;
  pipeline::LoopClosureConfig& loop = odometry.loop;
  if (preset == Preset::kDrover) {
    odometry.degenerate_pose_from_match = false;
    f.factor = f.initial_guess = true;
    f.factor_degenerate_only = f.initial_guess_degenerate_only = true;  // where the lidar does not hold the pose
    f.reset_after = pipeline::VisualMotionConfig{}.reset_after;
    f.keyframe_gap_velocity_tolerance = kKeyframeGapVelocityTolerance;
    // Scan Context finds the places the odometry has drifted far from (the farm's seeds 1 and 2 after the white
    // walls); the radius search beside it (LIO-SAM's 15 m) the parallel passes a few metres apart that Scan Context's
    // descriptor does not match (farm seed 3: 400-408 s against 615-624 s, 12-14 m apart; bench/RESULTS.md).
    loop.source = pipeline::LoopSource::kBoth;
    loop.radius = 15.0;
    loop.yaw_prior = loop.visual_yaw_prior = true;
    // VINS-Mono's 4-DoF pose graph: loops correct x, y, z and yaw; roll and pitch stay as the IMU smoother found
    // them against gravity. A loop's tilt would restart the smoother on a tilt its accelerometer bias does not
    // belong to (g * 0.5 deg = 0.086 m/s^2): the LIS alone on the farm's seed 3 with LVI-SAM's radius loops drifted
    // to 5.6 m APE with the 6-DoF graph, 0.80 m with this one (bench/RESULTS.md).
    loop.four_dof_with_imu = true;
    // A loop's covariance widens with its fit's residual beyond 5 cm: the radius loops against the first keyframe at
    // the farm's end (fitness 0.15-0.18 m) were 1.2-2.2 deg off against the floors' 0.29 deg (NEES 20-28). Seeds 1-3
    // 0.269 -> 0.261, 0.222 -> 0.222, 0.295 -> 0.288 m; kitti05-replay's LIS 0.162 -> 0.156 m (bench/RESULTS.md).
    loop.verifier.sigma_fitness_reference = 0.05;
  } else if (preset == Preset::kLviSam) {
    f.factor = false;
    f.initial_guess = true;
    f.initial_guess_degenerate_only = false;  // updateInitialGuess: the VIS's motion on every sweep
    withoutGates(f);
    // LIO-SAM / LVI-SAM params_lidar.yaml: historyKeyframeSearchRadius 15 m, historyKeyframeSearchTimeDiff 30 s,
    // keyframes every 1 m or 0.2 rad.
    loop.source = pipeline::LoopSource::kRadius;
    loop.radius = 15.0;
    loop.min_age = 30.0;
    loop.yaw_prior = loop.visual_yaw_prior = false;
    odometry.keyframes.distance = 1.0;
    odometry.keyframes.angle = 0.2;
    // mapOptimization's pose is the scan match, its degenerate directions kept at the (VIS) guess.
    odometry.degenerate_pose_from_match = true;
    loop.four_dof_with_imu = false;  // LIO-SAM's keyframe graph (iSAM2) corrects all 6 DoF
    loop.verifier.sigma_fitness_reference = 0.0;  // its loop noise is the ICP fitness score alone
    odometry.static_hold.sigma = 0.0;              // LIO-SAM's IMU graph knows only its first velocity
    odometry.matcher.degeneracy_threshold_per_correspondence = 0.0;  // its fixed eigenvalue threshold alone
  }
}

void applyPreset(Preset preset, io::VisualConfig& visual, vio::VioConfig& vio) {
  if (preset == Preset::kDrover) {
    visual.detector.type = visual::DetectorType::kSuperPoint;
    vio.depth_mode = vio::DepthMode::kFactor;
    if (vio.max_keyframe_interval_s <= 0) vio.max_keyframe_interval_s = kKeyframeInterval;
  } else if (preset == Preset::kLviSam) {
    // LVI-SAM params_camera.yaml: max_cnt 150, min_dist 20, F_threshold 1.0, keyframe_parallax 10, window 10.
    visual.detector.type = visual::DetectorType::kShiTomasi;
    visual.tracker.max_features = 150;
    visual.tracker.min_distance = 20;
    visual.tracker.ransac_threshold_px = 1.0;
    vio.min_parallax_px = 10;
    vio.max_keyframe_interval_s = 0;  // VINS-Mono's keyframes come by parallax (or few tracks) alone
    vio.window = 10;
    vio.depth_mode = vio::DepthMode::kFixed;
    // Its feature_tracker calls cv::calcOpticalFlowPyrLK with the default minEigThreshold.
    visual.tracker.min_eigenvalue = visual::FeatureTrackerConfig{}.min_eigenvalue;
    visual.tracker.top_up_below = 0;  // its detector is the corners already
    visual.tracker.detect_sync_below = 0;
  }
}

std::vector<std::string> partNames() {
  return {"vo-factor",     "vis-guess", "vis-gates",          "visual-yaw-prior", "scan-context",
          "radius-search", "four-dof",  "loop-fitness-sigma", "vis-carried-sigma", "depth-factor",
          "superpoint",    "lk-min-eigenvalue", "keyframe-interval", "keyframe-gap-speed", "lidar-rotation-sigma"};
}

void removePart(const std::string& part, pipeline::OdometryConfig& odometry) {
  const std::vector<std::string> names = partNames();
  if (std::find(names.begin(), names.end(), part) == names.end())
    throw std::invalid_argument("--without: unknown part '" + part + "'");
  if (part == "vo-factor") odometry.vis_fusion.factor = false;
  if (part == "vis-guess") odometry.vis_fusion.initial_guess = false;
  if (part == "vis-gates") withoutGates(odometry.vis_fusion);
  if (part == "visual-yaw-prior") odometry.loop.visual_yaw_prior = false;
  if (part == "scan-context") odometry.loop.source = pipeline::LoopSource::kRadius;
  if (part == "radius-search") odometry.loop.source = pipeline::LoopSource::kScanContext;
  if (part == "four-dof") odometry.loop.four_dof_with_imu = false;
  if (part == "loop-fitness-sigma") odometry.loop.verifier.sigma_fitness_reference = 0.0;
  if (part == "vis-carried-sigma") odometry.loop.vis_carried_sigma = 0.0;
  if (part == "keyframe-gap-speed") odometry.vis_fusion.keyframe_gap_velocity_tolerance = 0.0;
}

void removePart(const std::string& part, io::VisualConfig& visual, vio::VioConfig& vio) {
  if (part == "depth-factor") vio.depth_mode = vio::DepthMode::kFixed;
  if (part == "superpoint") visual.detector.type = visual::DetectorType::kShiTomasi;
  if (part == "keyframe-interval") vio.max_keyframe_interval_s = 0;
}

std::string MethodChoice::describe() const {
  std::string s = presetName(preset);
  for (std::size_t i = 0; i < without.size(); ++i) s += (i == 0 ? " without " : ", ") + without[i];
  return s;
}

void MethodChoice::apply(pipeline::OdometryConfig& odometry) const {
  applyPreset(preset, odometry);
  for (const std::string& part : without) removePart(part, odometry);
  // After the parts, as the LK threshold below: a platform file's tighter sigma stays.
  if (preset == Preset::kDrover && !withoutPart("lidar-rotation-sigma")) {
    if (odometry.lidar_sigma_rotation_unaided <= 0)
      odometry.lidar_sigma_rotation_unaided = odometry.lidar_sigma_rotation;  // the platform's, before it tightens
    odometry.lidar_sigma_rotation = std::min(odometry.lidar_sigma_rotation, kLidarSigmaRotation);
  }
}

bool MethodChoice::withoutPart(const std::string& part) const {
  return std::find(without.begin(), without.end(), part) != without.end();
}

void MethodChoice::apply(io::VisualConfig& visual, vio::VioConfig& vio) const {
  applyPreset(preset, visual, vio);
  for (const std::string& part : without) removePart(part, visual, vio);
  // After the parts: the threshold is for SuperPoint's tracks, so --without superpoint leaves it as the platform's.
  const bool gate = !withoutPart("lk-min-eigenvalue");
  // A platform's corner top-up (tracker.top_up_below; off in the presets: it failed the farm's fault course, see
  // bench/RESULTS.md) keeps its own LK floor for the corners (tracker.top_up_min_eigenvalue).
  if (preset == Preset::kDrover && gate && visual.detector.type == visual::DetectorType::kSuperPoint)
    visual.tracker.min_eigenvalue = std::max(visual.tracker.min_eigenvalue, kSuperPointMinEigenvalue);
  // Shi-Tomasi (--without superpoint, the lvi-sam preset) is the corners already: no top-up, live or replayed.
  if (visual.detector.type == visual::DetectorType::kShiTomasi) {
    visual.tracker.top_up_below = 0;
    visual.tracker.detect_sync_below = 0;
  }
}

}  // namespace drover::cli
