#pragma once
// drover run --preset: the paper's comparison, rerunnable on any dataset Drover reads. A preset sets the methods;
// the platform file still sets the sensors, their calibration and every value the preset does not name. Without
// --preset the platform file holds as it is (its shipped defaults are the drover preset's, but for the detector of
// platforms without SuperPoint weights and the lidar-depth mode).
//   lvi-sam: LVI-SAM as released (Shan et al., ICRA 2021; github.com/TixiaoShan/LVI-SAM): Shi-Tomasi + KLT (VINS-Mono
//            max_cnt 150, min_dist 20, F_threshold 1), lidar depth held fixed, the VIS's motion as the scan
//            matcher's guess whenever the VIS has an estimate (no visual odometry factor: LVI-SAM issue #7; none of
//            Drover's health gates, no reset of the VIS by the LIS), a degenerate match's pose the match's own (its
//            degenerate directions at the guess, as LIO-SAM's mapOptimization), loop closure by the nearest old keyframe within
//            15 m and 30 s verified by ICP (no Scan Context). Its visual DBoW2 loop detector is not reproduced.
//   drover:  SuperPoint + KLT (SuperPoint's tracks held to a smallest gradient eigenvalue of 2e-3: none following a
//            plain wall's image noise or sliding along an edge), lidar depth as factors, the VIS's motion as guess
//            and factor behind the health gates with resets by the LIS, Scan Context with the VIS's yaw prior, the
//            scan match's attitude in the IMU smoother at 0.01 rad.
#include <string>
#include <vector>

#include "io/visual/visual_config_io.hpp"
#include "pipeline/odometry_config.hpp"
#include "vio/vio_config.hpp"

namespace drover::cli {

enum class Preset { kPlatform, kDrover, kLviSam };
std::vector<std::string> presetNames();             // "drover", "lvi-sam"
Preset presetFromName(const std::string& name);     // "" -> kPlatform; throws std::invalid_argument otherwise
const char* presetName(Preset preset);              // "platform", "drover", "lvi-sam"

void applyPreset(Preset preset, pipeline::OdometryConfig& odometry);
void applyPreset(Preset preset, io::VisualConfig& visual, vio::VioConfig& vio);

// drover run --without PART (the ablation's rows: the system without one of its parts, after the preset):
//   vo-factor (the VIS's motion as a factor), vis-guess (... as the matcher's guess), vis-gates (the health gates
//   and the reset by the LIS), visual-yaw-prior (loop closure's VIS yaw), scan-context (radius loops instead),
//   depth-factor (lidar depth held fixed instead), superpoint (Shi-Tomasi instead), lk-min-eigenvalue (SuperPoint's
//   tracks at the platform's LK threshold), keyframe-interval (the VIS's keyframes by parallax alone, as VINS-Mono),
//   keyframe-gap-speed (every keyframe gap while moving a stall, whatever the VIS's velocity), lidar-rotation-sigma
//   (the scan match's attitude in the IMU smoother at the platform's sigma, LIO-SAM's 0.05 rad, instead of 0.01 rad).
std::vector<std::string> partNames();

// A run's choice: the preset, then the parts taken out.
struct MethodChoice {
  Preset preset = Preset::kPlatform;
  std::vector<std::string> without;
  std::string describe() const;  // "drover", "drover without vo-factor, superpoint", "platform"
  void apply(pipeline::OdometryConfig& odometry) const;
  void apply(io::VisualConfig& visual, vio::VioConfig& vio) const;
  bool withoutPart(const std::string& part) const;
};
// Throws std::invalid_argument for an unknown part.
void removePart(const std::string& part, pipeline::OdometryConfig& odometry);
void removePart(const std::string& part, io::VisualConfig& visual, vio::VioConfig& vio);

}  // namespace drover::cli
