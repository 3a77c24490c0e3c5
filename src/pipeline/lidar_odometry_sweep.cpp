// LidarOdometry's per-sweep chain (LIO-SAM's mapOptimization, one sweep at a time): preprocessing, deskew and
// features, the scan-to-map match, the IMU smoother, keyframes and in-line loop closure.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "pipeline/lidar_odometry_impl.hpp"
#include "pipeline/motion_models.hpp"

namespace drover::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

// Sweeps are stamped at their start; t_imu = t_lidar + offset puts them on the IMU's clock.
std::vector<ScanOutcome> LidarOdometry::Impl::onScan(LidarScan scan) {
  ++stats.scans_in;
  scan.t += calibration.lidar_time_offset;
  scan.t_end += calibration.lidar_time_offset;
  const Time last = !pending.empty() ? pending.back().t : (!recent.empty() ? recent.back().t : scan.t - 1);
  if (scan.t <= last) {
    ++stats.scans_skipped_time;
    notice(fmt::format("sweep at {:.6f} s skipped: its stamp is not after the previous sweep's ({:.6f} s)",
                       toSeconds(scan.t), toSeconds(last)));
    return {};
  }
  pending.push_back(std::move(scan));
  return drain(false);
}

// Processes waiting sweeps in order: each once the IMU covers its end (or at once without an IMU); when `force`,
// or when a later sweep is already imu_wait past a sweep's end, that sweep goes without full IMU coverage.
std::vector<ScanOutcome> LidarOdometry::Impl::drain(bool force) {
  std::vector<ScanOutcome> out;
  while (!pending.empty()) {
    LidarScan& scan = pending.front();
    const Time end = fusion.coverageNeeded(scan.t, std::max(scan.t, scan.t_end), recent.empty());
    const bool waiting = fusion.wantsImu() && fusion.latestImuTime() < end;
    const bool overdue = pending.back().t > end + fromSeconds(config.imu_wait);
    if (waiting && !force && !overdue) break;
    if (std::optional<ScanOutcome> o = processScan(scan)) out.push_back(std::move(*o));
    pending.pop_front();
  }
  return out;
}

std::optional<ScanOutcome> LidarOdometry::Impl::processScan(LidarScan& scan) {
  const auto t_start = Clock::now();
  ScanOutcome out;
  out.t = scan.t;
  auto t0 = Clock::now();
  if (!preprocess(scan, out)) return std::nullopt;
  out.ms.preprocess = msSince(t0);

  if (config.use_imu) fusion.tryInitialize(scan.t, recent.empty());
  std::optional<lidar::SweepMotion> motion;
  if (config.deskew) {
    motion = fusion.sweepMotion(scan.t, scan.t_end);
    out.imu_used = motion.has_value();
    if (!motion && recent.size() >= 2) {
      const StampedPose& a = recent[recent.size() - 2];
      const StampedPose& b = recent.back();
      motion = lidar::constantVelocityMotion(a.T_world_body.inverse() * b.T_world_body, toSeconds(b.t - a.t));
    }
  }
  bool from_imu = false;
  const Eigen::Isometry3d T_guess = guess(scan.t, from_imu, out);
  out.imu_used = out.imu_used || from_imu;
  lidar::FeatureSet features = deskewAndExtract(scan, motion, out);
  match(features, T_guess, out);
  // Constant-velocity deskew: again with the sweep's own estimated motion (see deskew_refinements).
  const bool refine = motion && !out.imu_used && !recent.empty() && map.size() > map_first_keyframe;
  for (int k = 0; refine && out.match_usable && k < config.deskew_refinements; ++k) {
    const StampedPose& prev = recent.back();
    motion = lidar::constantVelocityMotion(prev.T_world_body.inverse() * out.T_world_lidar, toSeconds(scan.t - prev.t));
    features = deskewAndExtract(scan, motion, out);
    match(features, out.T_world_lidar, out);
  }
  countMatch(out);

  t0 = Clock::now();
  fusion.update(out, recent);
  out.ms.smoother = msSince(t0);
  if (out.reset) {
    ++stats.smoother_resets;
    stats.reset_times.push_back(scan.t);
  }
  if (out.imu_used) ++stats.imu_scans;
  if (out.vis_guess) ++stats.vis_guess_scans;
  if (out.vis_factor) ++stats.vis_factor_scans;
  if (!out.vis_reset.empty()) ++stats.vis_resets_requested;

  accumulateDegeneracy(out);
  if (sweep_listener) sweep_listener(scan.t, out.T_world_lidar, features.full);
  keyframe(features, out);
  record(out);
  ++stats.scans_processed;
  stats.imu_initialized = fusion.initialized();
  stats.imu_init = fusion.initNote();
  out.ms.total = msSince(t_start);
  return out;
}

// Drops bad points and fills in ring/time when the lidar gives none; false when too little is left.
bool LidarOdometry::Impl::preprocess(LidarScan& scan, ScanOutcome& out) {
  const lidar::SanitizeResult s = lidar::sanitize(scan, config.layout);
  // Readers drop non-finite points themselves (LidarScan::dropped_nonfinite); sanitize catches any that remain.
  const std::size_t non_finite = s.non_finite + scan.dropped_nonfinite;
  stats.points_nonfinite += non_finite;
  stats.points_dropped += non_finite + s.too_close + s.too_far;
  if (non_finite > 0) out.warning = fmt::format("{} non-finite points dropped", non_finite);
  out.points = scan.points.size();
  if (static_cast<int>(scan.points.size()) < config.min_points) {
    ++stats.scans_skipped_empty;
    notice(fmt::format("sweep at {:.6f} s skipped: {} valid points (fewer than min_points = {})", toSeconds(scan.t),
                       scan.points.size(), config.min_points));
    return false;
  }
  if (!scan.has_time) lidar::inferTimes(scan, config.layout);
  if (!scan.has_ring) lidar::inferRings(scan, config.layout);
  if (scan.t_end <= scan.t) scan.t_end = scan.t + fromSeconds(config.layout.scan_period);
  return true;
}

// The VIS's motion since the previous sweep while a healthy VIS runs (LVI-SAM; with initial_guess_degenerate_only
// only after a degenerate sweep), else the IMU prediction when the fusion is running, else constant velocity from
// the last two poses.
Eigen::Isometry3d LidarOdometry::Impl::guess(Time t, bool& from_imu, ScanOutcome& out) const {
  const bool vis_wanted = !config.vis_fusion.initial_guess_degenerate_only || degenerate_run > 0;
  if (!recent.empty() && vis_wanted) {
    if (std::optional<Eigen::Isometry3d> p = fusion.visualLidarGuess(t, recent.back(), &out.vis_unused)) {
      out.vis_guess = from_imu = true;  // the VIS's motion is visual-inertial
      return *p;
    }
  }
  if (std::optional<Eigen::Isometry3d> p = fusion.predictLidarPose(t)) {
    from_imu = true;
    return *p;
  }
  from_imu = false;
  if (recent.empty()) return fusion.initialLidarPose();
  if (recent.size() == 1) return recent.back().T_world_body;
  const StampedPose& a = recent[recent.size() - 2];
  const StampedPose& b = recent.back();
  return constantVelocityGuess(b.T_world_body, a.T_world_body.inverse() * b.T_world_body, toSeconds(b.t - a.t),
                               toSeconds(t - b.t));
}

lidar::FeatureSet LidarOdometry::Impl::deskewAndExtract(const LidarScan& scan,
                                                        const std::optional<lidar::SweepMotion>& motion,
                                                        ScanOutcome& out) const {
  auto t0 = Clock::now();
  const LidarScan deskewed = motion ? deskewer.deskew(scan, *motion).scan : scan;
  out.ms.deskew += msSince(t0);
  t0 = Clock::now();
  lidar::FeatureSet features = extractor.extract(deskewed).features;
  out.edges = features.edges.size();
  out.planes = features.planes.size();
  out.ms.features += msSince(t0);
  return features;
}

void LidarOdometry::Impl::match(const lidar::FeatureSet& features, const Eigen::Isometry3d& T_guess,
                                ScanOutcome& out) {
  out.T_world_lidar = T_guess;
  if (map.size() <= map_first_keyframe) {
    out.match_status = "first";
    out.converged = out.match_usable = true;
    return;
  }
  auto t0 = Clock::now();
  map.build(T_guess.translation(), map_first_keyframe);
  out.ms.map += msSince(t0);
  t0 = Clock::now();
  const lidar::MatchResult r = matcher.align(features, map, T_guess);
  out.ms.match += msSince(t0);
  out.T_world_lidar = r.T_world_lidar;
  out.match_status = lidar::toString(r.status);
  out.converged = r.converged;
  out.degenerate = r.degenerate;
  out.degenerate_count = r.degenerate_count;
  out.degenerate_directions = r.degenerate_directions;
  out.min_eigenvalue = r.eigenvalues.minCoeff();
  out.iterations = r.iterations;
  out.fitness = r.fitness;
  out.edge_inliers = r.edge_inliers;
  out.plane_inliers = r.plane_inliers;
  out.match_usable = r.status == lidar::MatchStatus::kConverged || r.status == lidar::MatchStatus::kMaxIterations;
  out.match_reason = r.reason;
  if (!out.match_usable) out.T_world_lidar = T_guess;
}

// Counts the final match of a sweep (refinements re-match the same sweep).
void LidarOdometry::Impl::countMatch(ScanOutcome& out) {
  if (out.degenerate) {
    ++stats.degenerate_scans;
    stats.degenerate_times.push_back(out.t);
  }
  if (!out.match_usable) {
    ++stats.not_converged;
    out.warning += (out.warning.empty() ? "" : "; ") + std::string("match failed (") + out.match_reason +
                   "): pose predicted";
  }
}

void LidarOdometry::Impl::keyframe(const lidar::FeatureSet& features, ScanOutcome& out) {
  const bool first = map.size() == 0;
  const int n = config.degenerate_restart_sweeps;
  const bool was_long = n > 0 && degenerate_run >= n;
  degenerate_run = out.degenerate ? degenerate_run + 1 : 0;
  // Restart when a long degenerate stretch begins (older keyframes disagree with the drifting pose) and again when
  // it ends (the stretch's own keyframes are stretched or squeezed along the degenerate direction).
  const bool restart = n > 0 && (degenerate_run == n || (was_long && degenerate_run == 0));
  if (restart) {
    map_first_keyframe = map.size();
    stats.map_restart_times.push_back(out.t);
    out.warning += std::string(out.warning.empty() ? "" : "; ") +
                   (degenerate_run == n ? fmt::format("{} degenerate sweeps in a row: local map restarted", n)
                                        : std::string("end of a degenerate stretch: local map restarted"));
  }
  if (!first && !restart && !policy.isKeyframe(T_world_lastkf, out.T_world_lidar)) return;

  const std::size_t index = map.addKeyframe(features, out.T_world_lidar);
  T_world_lastkf = out.T_world_lidar;
  prebuild_center = out.T_world_lidar.translation();
  out.keyframe = true;
  ++stats.keyframes;
  const auto t0 = Clock::now();
  const std::vector<std::pair<std::size_t, std::size_t>> retired = supersededKeyframes();
  if (keyframe_listener) {
    const Eigen::Isometry3d T_previous = index > 0 ? map.keyframe(index - 1).T_world_lidar : out.T_world_lidar;
    KeyframeRecord record{index, out.t, map.keyframe(index).shared, out.T_world_lidar,
                          T_previous.inverse() * out.T_world_lidar, degenerate_since_kf, {}, {}};
    for (const auto& [i, by] : retired) {
      record.retired.push_back(i);
      record.retired_by.push_back(by);
    }
    keyframe_listener(std::move(record));
  }
  const bool closed = !external_loops && loops.addKeyframe(map, index, degenerate_since_kf);
  degenerate_since_kf.setZero();
  if (closed) applyLoopCorrection(out);
  // After the search, as the live loop thread does it: this keyframe's search still saw the retired ones.
  for (const auto& [i, by] : retired) {
    map.retire(i);
    if (!external_loops) loops.retire(i, by);
  }
  stats.keyframes_retired += retired.size();
  out.ms.loop = msSince(t0);
}

// The keyframes superseded by those that became retire_age old with the newest keyframe (LocalMapConfig): each
// keyframe is looked at once, when it is that old, so its own loop search has long been made.
std::vector<std::pair<std::size_t, std::size_t>> LidarOdometry::Impl::supersededKeyframes() {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  const std::size_t newest = map.size() - 1;
  if (map.config().retire_radius <= 0) return out;
  const Time latest = map.keyframe(newest).t - fromSeconds(map.config().retire_age);
  for (; retire_next < newest && map.keyframe(retire_next).t <= latest; ++retire_next) {
    for (std::size_t i : map.supersededBy(retire_next)) out.emplace_back(i, retire_next);
  }
  // Sorted by the retired keyframe, its first (oldest) superseder kept.
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
            out.end());
  return out;
}

// What the pose graph is told about the sweeps between keyframes: each degenerate direction (and every direction
// of a failed match) loosens the odometry edge along it.
void LidarOdometry::Impl::accumulateDegeneracy(const ScanOutcome& out) {
  if (!out.match_usable) {
    degenerate_since_kf += geometry::Matrix6d::Identity();
    return;
  }
  // The VIS's motion carried the directions the match left open: the edge yields there by the VIS's sigma, not the
  // lidar's degenerate one (see LoopClosureConfig::vis_carried_sigma).
  const double w = out.vis_factor ? std::pow(config.loop.vis_carried_sigma / config.loop.degenerate_sigma, 2) : 1.0;
  if (w == 0.0) return;
  for (const geometry::Vector6d& d : out.degenerate_directions)
    degenerate_since_kf += w * d.normalized() * d.normalized().transpose();
}

// The graph moved the keyframes: the map, every sweep (through its keyframe), the current sweep and the IMU
// smoother follow. T_new_old maps the newest keyframe's old pose onto its corrected one.
void LidarOdometry::Impl::applyLoopCorrection(ScanOutcome& out) {
  out.T_new_old = correctKeyframes(loops.poses());
  fusion.reanchor(out.T_new_old);
  out.T_world_lidar = T_world_lastkf;
  out.loop_closed = true;
  stats.loop_times.push_back(out.t);
  const LoopEvent& e = loops.events().back();
  out.note = fmt::format("loop closed with keyframe {} ({:.1f} s earlier): trajectory corrected by {:.2f} m",
                             e.candidate, toSeconds(e.t_query - e.t_candidate), e.correction);
}

// Moves every keyframe (all of them: poses.size() == map.size()) and every sweep through its keyframe; returns
// T_new_old of the newest keyframe, which the IMU smoother follows.
Eigen::Isometry3d LidarOdometry::Impl::correctKeyframes(const std::vector<Eigen::Isometry3d>& poses) {
  const std::size_t last = poses.size() - 1;
  const Eigen::Isometry3d T_new_old = poses[last] * map.keyframe(last).T_world_lidar.inverse();
  for (std::size_t i = 0; i < poses.size(); ++i) map.updatePose(i, poses[i]);
  for (std::size_t i = 0; i < recent.size(); ++i)
    recent[i].T_world_body = poses[anchors[anchors.size() - recent.size() + i].keyframe] * recent_kf_sweep[i];
  T_world_lastkf = poses[last];
  prebuild_center = T_world_lastkf.translation();
  return T_new_old;
}

void LidarOdometry::Impl::record(const ScanOutcome& out) {
  const std::size_t kf = map.size() - 1;
  const Eigen::Isometry3d T_kf_sweep = map.keyframe(kf).T_world_lidar.inverse() * out.T_world_lidar;
  anchors.push_back({out.t, static_cast<std::uint32_t>(kf),
                     Eigen::Quaterniond(T_kf_sweep.linear()).normalized().cast<float>(),
                     T_kf_sweep.translation().cast<float>()});
  recent.push_back({out.t, out.T_world_lidar});
  recent_kf_sweep.push_back(T_kf_sweep);
  if (recent.size() > 2) {
    recent.erase(recent.begin());
    recent_kf_sweep.erase(recent_kf_sweep.begin());
  }
}

}  // namespace drover::pipeline
