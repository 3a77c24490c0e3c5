#include "apps/drover/loop_report.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

namespace drover::cli {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;
constexpr double kCorrectTranslation = 1.0;  // [m]
constexpr double kCorrectRotation = 5.0;     // [deg]
constexpr double kRevisitDistance = 3.0;     // [m]

// Ground-truth lidar pose at t: the nearest ground-truth pose (simulator: 200 Hz; KITTI: one per scan) times the
// lidar's pose on the body. Nothing when the nearest is more than 20 ms away.
class TruthLookup {
 public:
  explicit TruthLookup(const RunContext& c) : poses_(c.ground_truth.poses) {
    if (c.ground_truth.body_frame == "imu") T_body_lidar_ = c.calibration.T_imu_lidar;
  }
  bool empty() const { return poses_.empty(); }
  std::optional<Eigen::Isometry3d> lidarAt(Time t) const {
    if (poses_.empty()) return std::nullopt;  // no ground truth (a bag without it, a live run): nothing to look up
    auto it = std::lower_bound(poses_.begin(), poses_.end(), t, [](const StampedPose& p, Time v) { return p.t < v; });
    if (it == poses_.end() || (it != poses_.begin() && t - std::prev(it)->t < it->t - t)) --it;
    if (it == poses_.end() || std::abs(it->t - t) > 20'000'000) return std::nullopt;
    return it->T_world_body * T_body_lidar_;
  }

 private:
  const Trajectory& poses_;
  Eigen::Isometry3d T_body_lidar_ = Eigen::Isometry3d::Identity();
};

Json eventJson(const pipeline::LoopEvent& e, const TruthLookup& truth, bool& correct) {
  const loop::LoopVerification& v = e.verification;
  Json j{{"query", e.query},
         {"candidate", e.candidate},
         {"t_query", toSeconds(e.t_query)},
         {"t_candidate", toSeconds(e.t_candidate)},
         {"source", e.source},
         {"accepted", v.accepted},
         {"reason", v.reason},
         {"sc_distance", e.sc_distance},
         {"shift", e.shift},
         {"full_shift", e.full_shift},
         {"sc_yaw_deg", e.sc_yaw * kDeg},
         {"narrowed", e.narrowed},
         {"fell_back", e.fell_back},
         {"fitness_m", v.fitness},
         {"inliers", v.inliers},
         {"inlier_ratio", v.inlier_ratio},
         {"correction_from_guess_m", v.correction_translation},
         {"sigma_position_m", std::sqrt(v.covariance.topLeftCorner<3, 3>().trace() / 3)},
         {"sigma_rotation_deg", std::sqrt(v.covariance.bottomRightCorner<3, 3>().trace() / 3) * kDeg},
         {"graph_ms", e.graph_ms},
         {"graph_iterations", e.graph_iterations},
         {"graph_initial_cost", e.graph_initial_cost},
         {"graph_final_cost", e.graph_final_cost},
         {"trajectory_correction_m", e.correction},
         {"implied_drift_m", e.implied_drift},
         {"drift_budget_m", e.drift_budget},
         {"implied_rotation_deg", e.implied_rotation * kDeg},
         {"rotation_budget_deg", e.rotation_budget * kDeg}};
  correct = false;
  const auto a = truth.lidarAt(e.t_candidate), b = truth.lidarAt(e.t_query);
  if (a && b) {
    const Eigen::Isometry3d T_true = a->inverse() * *b;
    const Eigen::Isometry3d err = T_true.inverse() * v.T_candidate_query;
    const double et = err.translation().norm(), er = Eigen::AngleAxisd(err.linear()).angle() * kDeg;
    correct = et < kCorrectTranslation && er < kCorrectRotation;
    // The error normalised by the loop factor's own covariance (NEES, 6 DoF, decoupled [dp; dphi] as the graph
    // takes it): about 6 on average when the verifier's covariance is honest.
    geometry::Vector6d d;
    d << v.T_candidate_query.translation() - T_true.translation(), geometry::logSO3(err.linear());
    j["nees"] = d.dot(v.information() * d);
    j["true_distance_m"] = T_true.translation().norm();
    j["pose_error_m"] = et;
    j["pose_error_deg"] = er;
    j["correct"] = correct;
  }
  return j;
}

// Searched keyframes with a true revisit (see the header), and how many of them closed a correct loop.
void recall(const pipeline::LidarOdometry& odometry, const pipeline::LoopClosure& loops, const TruthLookup& truth,
            const std::vector<bool>& closed_ok, Json& j) {
  const Trajectory kfs = odometry.keyframeTrajectory();
  const Time min_age = fromSeconds(odometry.config().loop.min_age);
  std::vector<std::optional<Eigen::Vector3d>> p;
  for (const StampedPose& k : kfs) {
    const auto T = truth.lidarAt(k.t);
    p.push_back(T ? std::optional<Eigen::Vector3d>(T->translation()) : std::nullopt);
  }
  std::size_t revisits = 0, found = 0;
  for (std::size_t q = 0; q < kfs.size(); ++q) {
    if (!p[q] || !loops.searched(q)) continue;
    bool revisit = false;
    for (std::size_t i = 0; i < q && !revisit && kfs[i].t <= kfs[q].t - min_age; ++i)
      revisit = p[i] && (*p[i] - *p[q]).norm() < kRevisitDistance;
    if (!revisit) continue;
    ++revisits;
    if (closed_ok[q]) ++found;
  }
  j["searched_keyframes_with_revisit"] = revisits;
  j["recall"] = revisits ? static_cast<double>(found) / static_cast<double>(revisits) : 0.0;
}

}  // namespace

Json loopsJson(const RunContext& c, const pipeline::LidarOdometry& odometry, const pipeline::LoopClosure& loops) {
  const pipeline::LoopStats& s = loops.stats();
  const TruthLookup truth(c);
  Json j{{"enabled", loops.config().enabled},
         {"source", pipeline::toString(loops.config().source)},
         {"graph_dof", loops.config().graph.yaw_only_rotation ? 4 : 6},  // 4: x, y, z, yaw (roll, pitch kept)
         {"radius_m", loops.config().radius},  // the radius search's reach (radius and both sources)
         // a fit worse than this widens the loop's covariance by the squared ratio (0: off)
         {"sigma_fitness_reference_m", loops.config().verifier.sigma_fitness_reference},
         {"vis_carried_sigma", loops.config().vis_carried_sigma},
         {"queries", s.queries},
         {"candidates", s.candidates},
         {"verified", s.verified},
         {"accepted", s.accepted},
         {"over_drift_budget", s.over_drift_budget},
         {"shift_fallback", pipeline::toString(loops.config().shift_fallback)},
         {"visual_yaw_prior", loops.config().visual_yaw_prior},
         {"visual_priors", s.visual_priors},  // shift searches narrowed around the VIS's yaw (the rest: the estimate's)
         {"narrowed_searches", s.narrowed_searches},
         {"fallbacks", s.fallbacks},
         {"shifts_evaluated", s.shifts_evaluated},
         {"ms_total", s.total_ms},
         {"query_ms_mean", s.queries ? s.query_ms / static_cast<double>(s.queries) : 0.0},
         {"descriptor_ms_total", s.descriptor_ms},
         {"query_ms_total", s.query_ms},
         {"verify_ms_total", s.verify_ms},
         {"graph_ms_total", s.graph_ms},
         {"graph_nodes", loops.graphNodes()},
         {"retired_nodes_merged", s.merged}};
  Json events = Json::array();
  std::size_t correct = 0, judged = 0, same_shift = 0, compared = 0;
  std::vector<bool> closed_ok(odometry.keyframeTrajectory().size(), false);
  for (const pipeline::LoopEvent& e : loops.events()) {
    bool ok = false;
    events.push_back(eventJson(e, truth, ok));
    if (!e.verification.accepted || truth.empty() || !events.back().contains("correct")) continue;
    ++judged;
    if (!ok) continue;
    ++correct;
    closed_ok[e.query] = true;
    if (e.full_shift >= 0) {
      ++compared;
      if (e.full_shift == e.shift) ++same_shift;
    }
  }
  if (!truth.empty()) {
    j["precision"] = judged ? static_cast<double>(correct) / static_cast<double>(judged) : 1.0;
    j["correct"] = correct;
    recall(odometry, loops, truth, closed_ok, j);
    j["narrowed_equals_full_shift"] = compared ? static_cast<double>(same_shift) / static_cast<double>(compared) : 1.0;
    spdlog::info("loops: {} accepted of {} verified; against the ground truth precision {:.3f}, recall {:.3f}",
                 s.accepted, s.verified, j["precision"].get<double>(), j["recall"].get<double>());
  } else {
    spdlog::info("loops: {} accepted of {} verified", s.accepted, s.verified);
  }
  j["events"] = events;
  // Verified candidates older than the newest loop.max_events, left out of the list (and of precision and recall).
  j["events_dropped"] = loops.eventsDropped();
  return j;
}

}  // namespace drover::cli
