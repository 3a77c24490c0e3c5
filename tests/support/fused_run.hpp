#pragma once
// Drives the LIS and the VIS over a simulated course as `drover run` drives them: one time-ordered stream, the VIS
// started from the LIS and fed its sweeps, its motion fused into the LIS (tests/system/test_sim_corridor_fusion.cpp,
// test_sim_vis_lidar_depth.cpp).
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "io/odometry/odometry_config_io.hpp"
#include "io/visual/vio_config_io.hpp"
#include "io/visual/visual_config_io.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "pipeline/lis_seed.hpp"
#include "pipeline/visual_motion.hpp"
#include "support/live_course.hpp"
#include "visual/detector_factory.hpp"
#include "vio/visual_odometry.hpp"

namespace drover::test {

struct FusedRun {
  pipeline::OdometryStats stats;
  std::size_t vis_frames = 0;
  std::size_t vis_resets = 0;        // the VIS's own (failure detection, an IMU gap)
  std::size_t resets_by_the_lis = 0;  // ScanOutcome::vis_reset done, as drover run does them
  double path = 0, end_error = 0;  // [m]
  Trajectory lis;                  // the LIS's sweep-rate poses
  std::size_t degenerate_places = 0;  // keyframes the loop search skipped as degenerate (skip_degenerate_places)
  Trajectory vis;                  // the VIS's own T_world_imu at every frame it estimated
  Time first_vis_factor = 0;        // [ns] the first sweep with the VIS's motion as a factor (0: none)
  std::size_t keyframe_gap_refusals = 0;  // sweeps the keyframe gate refused the VIS ("no keyframe for ...")
  std::size_t acceleration_refusals = 0;  // sweeps refused by max_acceleration_difference (its tilt and bias)
  std::vector<std::pair<Time, imu::ImuBias>> biases;  // the smoother's newest biases after each sweep that ran it
  std::vector<Time> resets;                           // sweeps where the smoother restarted
};

// The replay of `course` up to `until` (0: all of it); with `factor` false the VIS's motion is only the matcher's
// guess (drover run --without vo-factor); `tweak` changes the platform file's odometry settings, `vio_tweak` its
// VIS settings, `detector_tweak` its detector (Shi-Tomasi unless it says otherwise).
inline FusedRun runFused(const LiveCourse& course, Time until = 0, bool factor = true,
                         const std::function<void(pipeline::OdometryConfig&)>& tweak = {},
                         const std::function<void(vio::VioConfig&)>& vio_tweak = {},
                         const std::function<void(visual::DetectorConfig&)>& detector_tweak = {}) {
  const std::string yaml = std::string(DROVER_SOURCE_DIR) + "/config/farm_sim.yaml";
  pipeline::OdometryConfig odometry_config = io::loadOdometryConfig(yaml);
  odometry_config.vis_fusion.factor = factor;
  if (tweak) tweak(odometry_config);
  pipeline::LidarOdometry lis(odometry_config, course.calibration);
  vio::VisConfig vis_config;
  vis_config.vio = io::loadVioConfig(yaml);
  if (vio_tweak) vio_tweak(vis_config.vio);
  const io::VisualConfig visual = io::loadVisualConfig(yaml);
  vis_config.tracker = visual.tracker;
  vis_config.depth = visual.depth;
  visual::DetectorConfig detector = visual.detector;
  detector.type = visual::DetectorType::kShiTomasi;  // SuperPoint costs ~0.4 s a frame here
  if (detector_tweak) detector_tweak(detector);
  vio::VisualOdometry vo(vis_config, course.calibration, odometry_config.preintegration, visual::makeDetector(detector));
  lis.setSweepListener([&](Time t, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& p) {
    vo.addSweep(t, T, p);
  });
  pipeline::VisualStateStream states;
  std::optional<imu::ImuBias> lis_bias;
  FusedRun r;
  for (const Measurement& m : course.stream) {
    if (until > 0 && measurementTime(m) > until) break;
    if (const auto* frame = std::get_if<CameraFrame>(&m)) {
      const auto pose_at = [&](Time t) { return pipeline::lisPoseAt(lis.recentImuRate(), t); };
      const auto seed = [&](Time t) -> std::optional<vio::SeedState> {
        if (!lis_bias || lis.stats().scans_processed < pipeline::kLisSeedMinSweeps) return std::nullopt;
        return pipeline::lisSeedAt(lis.recentImuRate(), t, *lis_bias);
      };
      const vio::FrameResult f = vo.addFrame(*frame, pose_at, seed).estimate;
      r.vis_resets += f.reset ? 1 : 0;
      if (f.initialized) r.vis.push_back({f.t, f.T_world_imu});
      if (const std::optional<pipeline::VisualState> s = states.onFrame(f)) {
        lis.addVisualState(*s);
        ++r.vis_frames;
      }
      continue;
    }
    if (const auto* imu = std::get_if<ImuSample>(&m)) vo.addImu(*imu);
    for (const pipeline::ScanOutcome& o : lis.process(m)) {
      if (o.has_imu_state) {
        lis_bias = imu::ImuBias{o.gyro_bias, o.acc_bias};
        r.biases.emplace_back(o.t, *lis_bias);
      }
      if (o.reset) r.resets.push_back(o.t);
      if (o.vis_factor && r.first_vis_factor == 0) r.first_vis_factor = o.t;
      if (o.vis_unused.find("no keyframe for") != std::string::npos) ++r.keyframe_gap_refusals;
      if (o.vis_unused.find("accelerometer bias make") != std::string::npos) ++r.acceleration_refusals;
      if (!o.vis_reset.empty() && vo.estimator().initialized()) {
        vo.reset();
        ++r.resets_by_the_lis;
      }
    }
  }
  lis.finish();
  r.stats = lis.stats();
  r.degenerate_places = lis.loopClosure().stats().degenerate_places;
  const Trajectory& est = lis.trajectory();
  r.lis = est;
  const std::optional<Eigen::Isometry3d> T_truth_est = alignedByFirstSweep(est, course);
  if (!T_truth_est || truthAt(course.truth, est.back().t) == nullptr) return r;
  for (std::size_t i = 1; i < course.truth.size(); ++i)
    r.path += (course.truth[i].T_world_body.translation() - course.truth[i - 1].T_world_body.translation()).norm();
  r.end_error = sweepError(est.back(), *T_truth_est, course);
  return r;
}

}  // namespace drover::test
