#pragma once
// Loop closure of the LIS (LIO-SAM's loopClosureThread + the keyframe graph of mapOptimization, without globals):
// every keyframe becomes a pose-graph node linked to the previous one by its odometry; its Scan Context goes into
// the database; candidates come from Scan Context (ring-key retrieval, prior-narrowed shift search) and/or from a
// radius search around the current estimate (LIO-SAM's detectLoopClosureDistance); each is verified by scan
// matching against the candidate's submap (loop/loop_verifier.hpp) and, when accepted, becomes a loop edge and the
// graph is re-solved from the current poses. The caller (LidarOdometry) then moves its keyframe map, trajectory and
// IMU smoother onto the corrected poses, as LIO-SAM's correctPoses does after an iSAM2 update.
//
// Odometry edges get sigmas per keyframe step plus, along each direction the scan matcher reported degenerate in
// the sweeps since the previous keyframe, degenerate_sigma per such sweep: a loop then bends the trajectory where
// the lidar could not see (a featureless corridor) rather than everywhere. Deterministic, single-threaded.
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "backend/pose_graph.hpp"
#include "geometry/se3.hpp"
#include "lidar/local_map.hpp"
#include "loop/loop_verifier.hpp"
#include "loop/scan_context_database.hpp"

namespace drover::pipeline {

enum class LoopSource { kScanContext, kRadius, kBoth };
const char* toString(LoopSource source);  // "scancontext", "radius", "both"

// What a candidate's prior-narrowed shift search does when its window's best fails the threshold (see
// LoopClosureConfig::shift_fallback).
enum class ShiftFallback { kAlways, kBudget, kNever };
const char* toString(ShiftFallback fallback);  // "always", "budget", "never"

struct LoopClosureConfig {
  bool enabled = true;
  LoopSource source = LoopSource::kScanContext;
  loop::ScanContextDatabaseConfig database;  // descriptor (rings, sectors, radius, sensor height, threshold, dh)
  loop::LoopVerifierConfig verifier;
  bool yaw_prior = true;                  // narrow the shift search around the estimate's relative yaw (Eqs. 2-4)
  // While a VIS runs: narrow it around the VIS's relative yaw instead when the VIS tracked through both keyframes'
  // times without a reset (pipeline::VisualYawHistory, LVI-SAM's A +- dh), the estimate's otherwise.
  bool visual_yaw_prior = true;
  // The narrowed search's fall-back when the window's best fails the threshold. kAlways: the full search (the
  // paper's; every candidate that is another place then pays for both, 7 + 60 shifts per descriptor). kBudget: only
  // the shifts the rotation drift budget since the candidate allows (below, charged along the keyframe chain, so
  // never less than the acceptance check's), plus one sector for the descriptor's quantisation: a loop further off
  // the estimate's yaw would be refused by that budget anyway. With the defaults that is +-4 sectors after 19 m of
  // path, +-8 after 1 km, all 60 where the odometry was degenerate in rotation. A VisualYawPrior gets the budget
  // without the degenerate term (the VIS's yaw drifts with the path, and lidar degeneracy does not touch it). kNever: the window only (a true revisit whose
  // estimate drifted more than the window misses). Sectors: 2 pi / database.descriptor.sectors each.
  ShiftFallback shift_fallback = ShiftFallback::kBudget;
  double min_age = 30.0;                  // [s] candidates at least this much older than the query (LIO-SAM 30 s)
  int submap_keyframes = 10;              // [keyframes] on each side of the candidate in its verification submap
  int max_verifications = 2;              // [-] candidates verified per keyframe at most (best Scan Context first)
  int skip_after_loop = 2;                // [keyframes] no detection for this many keyframes after an accepted loop
  double radius = 10.0;                   // [m] radius source: nearest old keyframe within this distance (LIO-SAM 15 m)
  double odometry_sigma_position = 0.02;  // [m] per keyframe step
  double odometry_sigma_rotation = 0.002;  // [rad] per keyframe step
  double degenerate_sigma = 0.5;           // [m or rad] per degenerate sweep, along its degenerate directions
  // [m or rad] per degenerate sweep whose motion the VIS carried (its VO factor in the LIS's smoother), along its
  // degenerate directions, in place of degenerate_sigma: the VIS holds those directions, but not as tightly as the
  // lidar holds the rest (it drifted 0.3-0.7 m along the farm's corridor on seed 3). 0 holds them as tightly as the
  // lidar, and a loop's correction is spread over the lidar-tight stretches instead of where the drift was;
  // degenerate_sigma's 0.5 lets the graph bend the corridor freely. Farm seeds 1 / 2 / 3 with the drover preset,
  // APE rmse: 0 -> 0.261 / 0.222 / 0.288 m, 0.05 -> 0.245 / 0.211 / 0.241 m, 0.1 -> 0.236 / 0.219 / 0.222 m,
  // 0.5 -> 0.479 / 0.566 / 0.176 m (bench/RESULTS.md).
  double vis_carried_sigma = 0.1;
  // Drift budget: a verified loop is accepted only if it moves the query (relative to the candidate) by at most
  // max_drift_floor + max_drift_ratio * (path length between them) + degenerate_drift * (degenerate directions
  // reported by the sweeps between them). A loop that needs more than the odometry can have drifted is a false
  // one (a repeated structure: identical pens, a symmetric hall), however well the scans fit.
  double max_drift_floor = 2.0;   // [m]
  double max_drift_ratio = 0.15;  // [-] of the path length
  double degenerate_drift = 0.5;  // [m] per degenerate direction of a sweep
  // The same for the relative rotation: the loop may turn the query (relative to the candidate) by at most
  // max_rotation_drift_floor + max_rotation_drift_ratio * path + degenerate_rotation_drift per degenerate direction
  // (counted by its rotational share: |phi|^2 of the unit direction [rho; phi]).
  // A lidar-inertial odometry's heading drifts well under 1 deg per 100 m; a loop from a Scan Context shift half a
  // turn off (a symmetric barn fits as well turned round) would tell the graph to turn the robot round, a rotation
  // residual near pi where the log map is discontinuous, and such loops can break the graph's later solves.
  double max_rotation_drift_floor = 0.2;      // [rad] (11 deg)
  double max_rotation_drift_ratio = 0.0005;   // [rad/m] (2.9 deg per 100 m)
  double degenerate_rotation_drift = 0.05;    // [rad] per degenerate direction of a sweep
  // Both budgets are charged along the cheapest keyframe path between query and candidate where the accepted loops
  // are free shortcuts (pipeline/loop_drift_path.hpp): on a third pass the budget is the odometry since the place
  // was last tied by a loop, not the two laps of path between the keyframes' indices (33 deg over 750 m let a
  // third-lap loop turn a good estimate 31 deg towards a candidate whose own pose was off). With the 4-DoF graph
  // (four_dof_with_imu) this kept the farm hour's heading within 12 deg (25-56 deg without). Off by default: beside
  // the 6-DoF graph, whose second-lap corrections can let the corridor's velocity run away (below), the tight
  // budgets then refused the loops that would have pulled the map back (600 refused by lap 3; bench/RESULTS.md).
  bool budget_through_loops = false;
  // Retired keyframes keep their own graph node (LIO-SAM: the graph grows with time). Off by default: a retired
  // keyframe's node is merged into the newer keyframe that stands for its place (see retire()).
  bool keep_retired_nodes = false;
  // No loop where the odometry was degenerate within 2 keyframes of the query or the candidate (a featureless
  // corridor): there the scan match cannot fix the offset along the corridor and the candidate's own pose is what
  // loosened odometry edges left it, tens of metres off on the farm course; such loops pulled a good estimate 26 m
  // and 7 deg away on its third lap. Off by default: over the farm hour it kept the heading within 4 deg for two
  // laps more, but the corridor's passes then never coincide, so its keyframes never retire (peak +16 % by lap 3),
  // and an 18 deg jump still came in lap 3 (bench/RESULTS.md).
  bool skip_degenerate_places = false;
  // With the IMU fused (OdometryConfig::loopClosure), the pose graph corrects x, y, z and yaw only and leaves every
  // keyframe's roll and pitch as the odometry found them against gravity (VINS-Mono's 4-DoF pose graph), and the
  // IMU smoother keeps its accelerometer bias at each correction (a turn about gravity does not change it). A 6-DoF
  // graph tilts the map by up to 1 deg (kitti05-replay); the smoother restarted on tilted poses reads g * tilt as
  // accelerometer bias (0.028 -> 0.13 m/s^2 over the farm's second lap), which the degenerate corridor then
  // integrates into a runaway velocity (6 m/s after 50 s, 234 m of drift). With budget_through_loops, the farm hour
  // (6 laps) keeps a median error of 0.6-0.7 m a lap and a peak memory of 1.17x the first lap's (with neither:
  // 1.48x, median errors up to 24 m a lap, heading errors up to 56 deg). Off in the platform files, on in the drover
  // preset: on one pass of the farm the LIS alone went from 3.58 to 4.58 m APE with it (in and after the corridor,
  // where the 6-DoF graph's tilts also take up the height drift: accelerometer bias and tilt are one unknown until
  // the heading turns); on kitti05-replay's LIS it is better (0.156 against 0.185 m with Scan Context's loops)
  // (bench/RESULTS.md).
  bool four_dof_with_imu = false;
  // Verified candidates kept for events() (report.json's list), the newest: past max_events the oldest half is
  // dropped (eventsDropped() counts them), so a day-long run holds at most this many (~1 KB each) instead of every
  // one (the farm course driven for an hour verifies ~2700). 0 keeps every event.
  int max_events = 8192;
  backend::PoseGraphConfig graph;
  std::string validate() const;  // empty when valid
};

// [sectors] How far the fall-back of a candidate's estimate-narrowed shift search reaches (loop::YawPrior) under
// config.shift_fallback: kAlways every shift (YawPrior::kFullFallback), kNever 0, kBudget the rotation drift budget
// over `path` [m] of odometry with `degenerate_rotation` degenerate rotational directions on the way, in sectors
// rounded up, plus one.
int shiftFallbackRadius(const LoopClosureConfig& config, double path, double degenerate_rotation);

// One verified candidate, accepted or not.
struct LoopEvent {
  std::size_t query = 0, candidate = 0;  // keyframe indices
  Time t_query = 0, t_candidate = 0;     // [ns]
  std::string source;                    // "scancontext" or "radius"
  double sc_distance = -1;               // [-] Scan Context distance (-1 for radius candidates)
  int shift = 0;                         // [sectors]
  double sc_yaw = 0;                     // [rad] yaw of the query in the candidate frame from the shift
  bool narrowed = false, fell_back = false;
  int full_shift = -1;  // the full search's shift on the same descriptors (to compare; -1: radius)
  loop::LoopVerification verification;
  double graph_initial_cost = 0, graph_final_cost = 0, graph_ms = 0;  // of the re-solve (accepted only)
  int graph_iterations = 0;                                            // of the re-solve (accepted only)
  double correction = 0;                       // [m] how far the re-solve moved the query keyframe
  double implied_drift = 0, drift_budget = 0;  // [m] |loop - estimate| of the relative translation, and its limit
  double implied_rotation = 0, rotation_budget = 0;  // [rad] angle of loop vs estimate relative rotation, limit
};

struct LoopStats {
  std::size_t queries = 0;     // keyframes searched
  std::size_t candidates = 0;  // Scan Context candidates under the threshold, plus radius candidates
  std::size_t verified = 0, accepted = 0;
  std::size_t over_drift_budget = 0;                 // verified by scan matching but rejected by the drift budget
  std::size_t narrowed_searches = 0, fallbacks = 0;  // prior-narrowed shift searches, and their fall-backs
  std::size_t visual_priors = 0;                     // shift searches whose prior came from the VisualYawPrior
  std::size_t retired = 0;                           // keyframes retired (retire()): no longer candidates
  std::size_t merged = 0;                            // of them, graph nodes merged into a newer keyframe's
  std::size_t unmerged = 0;                          // of them, kept as nodes: no accepted loop linked the places
  std::size_t degenerate_places = 0;                 // queries not searched and candidates dropped: degenerate there
  std::size_t shifts_evaluated = 0;                  // column-distance evaluations of the shift searches
  double descriptor_ms = 0, query_ms = 0, verify_ms = 0, graph_ms = 0;  // totals [ms]
  double total_ms = 0;  // [ms] every addKeyframe call, whole: the loop stage's own time (graph upkeep included)
};

// A yaw prior from another subsystem (the VIS's relative rotation between two keyframes' times, when it tracked
// through both): the yaw [rad] of the query keyframe's lidar in the candidate's, p_candidate = Rz(yaw) p_query, or
// nothing when it has none. Arguments: candidate and query keyframe times [ns].
using VisualYawPrior = std::function<std::optional<double>(Time t_candidate, Time t_query)>;

class LoopClosure {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit LoopClosure(const LoopClosureConfig& config);
  ~LoopClosure();
  LoopClosure(const LoopClosure&) = delete;
  LoopClosure& operator=(const LoopClosure&) = delete;

  // Called once per keyframe right after map.addKeyframe (index = its map index, in order). degenerate_cov is
  // the sum over the sweeps since the previous keyframe of d d^T for each unit degenerate direction d ([rho; phi],
  // lidar frame). Returns true when a loop was accepted and the graph re-solved: then poses() differ from the map's.
  bool addKeyframe(const lidar::LocalMap& map, std::size_t index, const geometry::Matrix6d& degenerate_cov);

  // The shift search's prior comes from `prior` when it returns one, else from the current estimate (when
  // config.yaw_prior). An empty function removes it. The VIS fills this in later; until then only the estimate.
  void setVisualYawPrior(VisualYawPrior prior);
  // Keyframe `index` was retired from the map (LocalMap::retire) because keyframe `by` (newer) stands for its
  // place: its Scan Context leaves the database, it is no longer a radius candidate, and, when an accepted loop
  // joins the two places (a loop between keyframes within submap_keyframes of each), its graph node is merged into
  // `by`'s (PoseGraph::mergeNode): their relative pose at the current estimate is held rigid from now on and
  // poses() gives it as `by`'s pose times that. So the graph, like the map, grows with the area driven, not the
  // time (with keep_retired_nodes, or without such a loop, the node stays free). Call after retiring it in the map
  // given to addKeyframe. Throws std::invalid_argument for an unknown index or by <= index.
  void retire(std::size_t index, std::size_t by);
  std::size_t graphNodes() const;  // nodes in the pose graph (keyframes less the merged ones)
  std::size_t descriptorBytes() const;  // [bytes] the database's stored descriptors

  std::vector<Eigen::Isometry3d> poses() const;  // T_world_lidar of every keyframe from the graph, by index
  bool searched(std::size_t index) const;        // keyframe `index` was queried for loops (not skipped)
  // The verified candidates, oldest first: every one, or the newest ones once more than config.max_events were
  // verified (events()[i] is the (eventsDropped() + i)-th of the run).
  const std::vector<LoopEvent>& events() const;
  std::size_t eventsDropped() const;
  const LoopStats& stats() const;
  const LoopClosureConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drover::pipeline
