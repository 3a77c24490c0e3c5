#include "pipeline/loop_closure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>

#include "geometry/so3.hpp"
#include "pipeline/loop_drift_path.hpp"

namespace drover::pipeline {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// A candidate before verification: where it came from and the guess of the query in its frame.
struct Candidate {
  std::size_t index = 0;
  std::string source;
  Eigen::Isometry3d T_candidate_query_guess = Eigen::Isometry3d::Identity();
  std::optional<loop::LoopCandidate> sc;
};

}  // namespace

struct LoopClosure::Impl {
  LoopClosureConfig config;
  loop::ScanContextDatabase database;
  loop::LoopVerifier verifier;
  backend::PoseGraph graph;
  std::vector<Time> times;
  std::vector<bool> searched;             // by keyframe
  std::vector<double> degenerate_before;  // by keyframe: degenerate directions reported up to it (cumulative)
  std::vector<double> degenerate_rotation_before;  // the same, their rotational share only (|phi|^2 of each)
  std::vector<double> path_before;  // [m] by keyframe: the odometry's path length up to it, as it was added
  std::vector<LoopEvent> events;
  std::size_t events_dropped = 0;  // the oldest, erased past config.max_events
  LoopStats stats;
  VisualYawPrior visual_prior;
  int skip = 0;
  // By keyframe: the newer keyframe its graph node was merged into (-1: its own node) and its pose in that one's.
  struct Merged {
    long long into = -1;
    Eigen::Quaterniond q_into_kf = Eigen::Quaterniond::Identity();
    Eigen::Vector3d p_into_kf = Eigen::Vector3d::Zero();
  };
  std::vector<Merged> merged;
  std::vector<std::pair<std::size_t, std::size_t>> accepted_loops;  // (candidate, query) keyframe indices

  // The odometry reported a degenerate direction (or a failed match) between keyframes i - 2 and i + 2.
  bool degeneratePlace(std::size_t i) const {
    const std::size_t a = i >= 2 ? i - 2 : 0, b = std::min(i + 2, degenerate_before.size() - 1);
    return degenerate_before[b] > degenerate_before[a];
  }

  // An accepted loop joins the neighbourhoods (+-submap_keyframes) of keyframes `older` and `newer`.
  bool loopBetween(std::size_t older, std::size_t newer) const {
    const auto near = [&](std::size_t a, std::size_t b) {
      return (a > b ? a - b : b - a) <= static_cast<std::size_t>(config.submap_keyframes);
    };
    return std::any_of(accepted_loops.begin(), accepted_loops.end(),
                       [&](const auto& l) { return near(l.first, older) && near(l.second, newer); });
  }

  explicit Impl(const LoopClosureConfig& c) : config(c), database(c.database), verifier(c.verifier), graph(c.graph) {}

  void addOdometryEdge(const lidar::LocalMap& map, std::size_t index, const geometry::Matrix6d& degenerate_cov);
  std::vector<Candidate> candidates(const lidar::LocalMap& map, std::size_t index,
                                    const loop::AugmentedScanContext& query);
  std::optional<Candidate> radiusCandidate(const lidar::LocalMap& map, std::size_t index) const;
  bool tryCandidate(const lidar::LocalMap& map, std::size_t index, const Candidate& c,
                    const loop::AugmentedScanContext& query);
  void checkDriftBudget(const lidar::LocalMap& map, LoopEvent& e);
};

LoopClosure::LoopClosure(const LoopClosureConfig& config) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("loop closure config: " + e);
  impl_ = std::make_unique<Impl>(config);
}

LoopClosure::~LoopClosure() = default;

// Sigma per keyframe step, plus degenerate_sigma^2 d d^T per degenerate sweep; the directions are in the sweeps'
// lidar frames, taken as the current keyframe's and rotated into the previous one's (the edge's `from` frame).
void LoopClosure::Impl::addOdometryEdge(const lidar::LocalMap& map, std::size_t index,
                                        const geometry::Matrix6d& degenerate_cov) {
  const Eigen::Isometry3d T_prev_cur =
      map.keyframe(index - 1).T_world_lidar.inverse() * map.keyframe(index).T_world_lidar;
  geometry::Matrix6d J = geometry::Matrix6d::Identity();
  J.topLeftCorner<3, 3>() = T_prev_cur.linear();
  geometry::Matrix6d cov = config.degenerate_sigma * config.degenerate_sigma * J * degenerate_cov * J.transpose();
  cov.diagonal().head<3>().array() += config.odometry_sigma_position * config.odometry_sigma_position;
  cov.diagonal().tail<3>().array() += config.odometry_sigma_rotation * config.odometry_sigma_rotation;
  geometry::Matrix6d information = cov.inverse();
  information = 0.5 * (information + information.transpose());
  graph.addEdge(static_cast<int>(index - 1), static_cast<int>(index), T_prev_cur, information,
                backend::EdgeKind::kOdometry);
}

bool LoopClosure::addKeyframe(const lidar::LocalMap& map, std::size_t index, const geometry::Matrix6d& degenerate_cov) {
  Impl& m = *impl_;
  if (index != m.times.size())
    throw std::invalid_argument(fmt::format("loop closure: keyframe {} given, {} expected", index, m.times.size()));
  const Clock::time_point t_call = Clock::now();
  const lidar::Keyframe& kf = map.keyframe(index);
  m.times.push_back(kf.t);
  m.searched.push_back(false);
  m.merged.emplace_back();
  m.degenerate_before.push_back((m.degenerate_before.empty() ? 0.0 : m.degenerate_before.back()) +
                                degenerate_cov.trace());
  m.degenerate_rotation_before.push_back(
      (m.degenerate_rotation_before.empty() ? 0.0 : m.degenerate_rotation_before.back()) +
      degenerate_cov.bottomRightCorner<3, 3>().trace());
  m.path_before.push_back(index == 0 ? 0.0
                                      : m.path_before.back() + (kf.T_world_lidar.translation() -
                                                                map.keyframe(index - 1).T_world_lidar.translation())
                                                                   .norm());
  m.graph.addNode(static_cast<int>(index), kf.T_world_lidar);
  if (index > 0) m.addOdometryEdge(map, index, degenerate_cov);
  if (!m.config.enabled) {
    m.stats.total_ms += msSince(t_call);
    return false;
  }

  auto t0 = Clock::now();
  const loop::AugmentedScanContext query =
      loop::makeAugmentedScanContext(kf.features().full, m.config.database.descriptor);
  m.stats.descriptor_ms += msSince(t0);
  bool closed = false;
  if (m.skip > 0) {
    --m.skip;
  } else if (m.config.skip_degenerate_places && m.degeneratePlace(index)) {
    ++m.stats.degenerate_places;
  } else {
    ++m.stats.queries;
    m.searched[index] = true;
    for (const Candidate& c : m.candidates(map, index, query)) {
      if (m.tryCandidate(map, index, c, query)) {
        closed = true;
        m.skip = m.config.skip_after_loop;
        break;
      }
    }
  }
  m.database.add(static_cast<int>(index), query.descriptors[0]);
  m.stats.total_ms += msSince(t_call);
  return closed;
}

// Scan Context candidates under the threshold (best first), then the radius candidate, each old enough; at most
// max_verifications, no candidate twice.
std::vector<Candidate> LoopClosure::Impl::candidates(const lidar::LocalMap& map, std::size_t index,
                                                     const loop::AugmentedScanContext& query) {
  std::vector<Candidate> out;
  const Time newest = times[index] - fromSeconds(config.min_age);
  const Eigen::Isometry3d& T_world_query = map.keyframe(index).T_world_lidar;
  if (config.source != LoopSource::kRadius) {
    auto t0 = Clock::now();
    auto prior = [&](int id) -> std::optional<loop::YawPrior> {
      const std::size_t candidate = static_cast<std::size_t>(id);
      if (visual_prior) {
        if (std::optional<double> v = visual_prior(times[candidate], times[index])) {
          ++stats.visual_priors;
          // The VIS drifts in yaw with the path as the estimate does, but lidar degeneracy does not touch it.
          return loop::YawPrior(*v, shiftFallbackRadius(config, path_before[index] - path_before[candidate], 0.0));
        }
      }
      if (!config.yaw_prior) return std::nullopt;
      return loop::YawPrior(
          geometry::yawOf(map.keyframe(candidate).T_world_lidar.linear().transpose() * T_world_query.linear()),
          shiftFallbackRadius(config, path_before[index] - path_before[candidate],
                              degenerate_rotation_before[index] - degenerate_rotation_before[candidate]));
    };
    const loop::DatabaseQuery q = database.query(query, prior);
    stats.query_ms += msSince(t0);
    stats.shifts_evaluated += static_cast<std::size_t>(q.shifts_evaluated);
    for (const loop::LoopCandidate& lc : q.candidates) {
      if (lc.match.match.narrowed) ++stats.narrowed_searches;
      if (lc.match.match.fell_back) ++stats.fallbacks;
      const std::size_t id = static_cast<std::size_t>(lc.id);
      if (lc.match.match.distance >= config.database.descriptor.threshold || times[id] > newest) continue;
      // Guess: the Scan Context yaw and lateral offset, with the estimate's relative tilt.
      const Eigen::Matrix3d R_est = map.keyframe(id).T_world_lidar.linear().transpose() * T_world_query.linear();
      Candidate c{id, "scancontext", loop::relativePoseFromMatch(lc.match, R_est), lc};
      out.push_back(c);
    }
  }
  if (config.source != LoopSource::kScanContext)
    if (std::optional<Candidate> r = radiusCandidate(map, index)) out.push_back(*r);
  std::vector<Candidate> unique;
  for (const Candidate& c : out) {
    if (config.skip_degenerate_places && degeneratePlace(c.index)) {
      ++stats.degenerate_places;
      continue;
    }
    const bool seen = std::any_of(unique.begin(), unique.end(), [&](const Candidate& u) { return u.index == c.index; });
    if (!seen && static_cast<int>(unique.size()) < config.max_verifications) unique.push_back(c);
  }
  stats.candidates += unique.size();
  return unique;
}

// The nearest keyframe (in the current estimate) within `radius` that is at least min_age older than the query.
std::optional<Candidate> LoopClosure::Impl::radiusCandidate(const lidar::LocalMap& map, std::size_t index) const {
  const Time newest = times[index] - fromSeconds(config.min_age);
  const Eigen::Isometry3d& T_world_query = map.keyframe(index).T_world_lidar;
  std::optional<Candidate> best;
  double best_d = config.radius;
  for (std::size_t i = 0; i < index && times[i] <= newest; ++i) {
    if (map.keyframe(i).retired) continue;
    const double d = (map.keyframe(i).T_world_lidar.translation() - T_world_query.translation()).norm();
    if (d < best_d) {
      best_d = d;
      best = Candidate{i, "radius", map.keyframe(i).T_world_lidar.inverse() * T_world_query, std::nullopt};
    }
  }
  return best;
}

// Verifies one candidate against its submap; when accepted adds the loop edge and re-solves the graph.
bool LoopClosure::Impl::tryCandidate(const lidar::LocalMap& map, std::size_t index, const Candidate& c,
                                     const loop::AugmentedScanContext& query) {
  const Time newest = times[index] - fromSeconds(config.min_age);
  const std::size_t n = static_cast<std::size_t>(config.submap_keyframes);
  const std::size_t first = c.index > n ? c.index - n : 0;
  std::vector<loop::SubmapKeyframe> submap;
  std::size_t candidate_in_submap = 0;
  for (std::size_t i = first; i <= c.index + n && i < index && times[i] <= newest; ++i) {
    if (map.keyframe(i).retired) continue;  // its clouds are gone (a candidate never is)
    if (i == c.index) candidate_in_submap = submap.size();
    submap.push_back({&map.keyframe(i).features(), map.keyframe(i).T_world_lidar});
  }
  LoopEvent e;
  e.query = index;
  e.candidate = c.index;
  e.t_query = times[index];
  e.t_candidate = times[c.index];
  e.source = c.source;
  if (c.sc) {
    e.sc_distance = c.sc->match.match.distance;
    e.shift = c.sc->match.match.shift;
    e.sc_yaw = c.sc->match.match.yaw;
    e.narrowed = c.sc->match.match.narrowed;
    e.fell_back = c.sc->match.match.fell_back;
    e.full_shift = loop::fullShiftSearch(database.descriptor(static_cast<int>(c.index)),
                                         query.descriptors[static_cast<std::size_t>(c.sc->match.index)])
                       .shift;
  }
  auto t0 = Clock::now();
  e.verification =
      verifier.verify(map.keyframe(index).features(), submap, candidate_in_submap, c.T_candidate_query_guess);
  stats.verify_ms += msSince(t0);
  ++stats.verified;
  if (e.verification.accepted) checkDriftBudget(map, e);
  if (e.verification.accepted) {
    const Eigen::Vector3d before = graph.pose(static_cast<int>(index)).translation();
    const std::size_t edge =
        graph.addEdge(static_cast<int>(c.index), static_cast<int>(index), e.verification.T_candidate_query,
                      e.verification.information(), backend::EdgeKind::kLoop);
    const backend::PoseGraphResult r = graph.optimize();
    e.graph_initial_cost = r.initial_cost;
    e.graph_final_cost = r.final_cost;
    e.graph_ms = r.time_ms;
    e.graph_iterations = r.iterations;
    stats.graph_ms += r.time_ms;
    if (!r.usable) {
      graph.setEdgeEnabled(edge, false);
      e.verification.accepted = false;
      e.verification.reason = "rejected: pose graph failed (" + r.reason + ")";
    } else {
      e.correction = (graph.pose(static_cast<int>(index)).translation() - before).norm();
      ++stats.accepted;
      accepted_loops.emplace_back(c.index, index);
    }
  }
  events.push_back(e);
  if (config.max_events > 0 && events.size() > static_cast<std::size_t>(config.max_events)) {
    const std::size_t drop = events.size() / 2;  // half at a time: amortised O(1) a verification
    events.erase(events.begin(), events.begin() + static_cast<std::ptrdiff_t>(drop));
    events_dropped += drop;
  }
  return e.verification.accepted;
}

// Rejects a verified loop that would move or turn the query further than the odometry can have drifted (see the
// config).
void LoopClosure::Impl::checkDriftBudget(const lidar::LocalMap& map, LoopEvent& e) {
  const Eigen::Isometry3d T_est =
      map.keyframe(e.candidate).T_world_lidar.inverse() * map.keyframe(e.query).T_world_lidar;
  e.implied_drift = (e.verification.T_candidate_query.translation() - T_est.translation()).norm();
  e.implied_rotation = geometry::rotationAngle(T_est.linear().transpose() * e.verification.T_candidate_query.linear());
  // What each odometry step adds to the budgets. Only the rotational share of the degenerate directions loosens the
  // rotation budget: a corridor's degenerate translation says nothing about the heading.
  // Without the loops as shortcuts the path is the chain from the candidate: the steps before it are never charged.
  std::vector<DriftStep> translation(e.query + 1), rotation(e.query + 1);
  for (std::size_t i = config.budget_through_loops ? 1 : e.candidate + 1; i <= e.query; ++i) {
    const double length =
        (map.keyframe(i).T_world_lidar.translation() - map.keyframe(i - 1).T_world_lidar.translation()).norm();
    translation[i] = {length, config.max_drift_ratio * length +
                                  config.degenerate_drift * (degenerate_before[i] - degenerate_before[i - 1])};
    rotation[i] = {length, config.max_rotation_drift_ratio * length +
                               config.degenerate_rotation_drift *
                                   (degenerate_rotation_before[i] - degenerate_rotation_before[i - 1])};
  }
  const std::vector<std::pair<std::size_t, std::size_t>> no_loops;
  const auto& shortcuts = config.budget_through_loops ? accepted_loops : no_loops;
  const DriftPath t_path = cheapestDriftPath(translation, shortcuts, e.query, e.candidate);
  const DriftPath r_path = cheapestDriftPath(rotation, shortcuts, e.query, e.candidate);
  e.drift_budget = config.max_drift_floor + t_path.cost;
  e.rotation_budget = config.max_rotation_drift_floor + r_path.cost;
  if (e.implied_drift <= e.drift_budget && e.implied_rotation <= e.rotation_budget) return;
  ++stats.over_drift_budget;
  e.verification.accepted = false;
  if (e.implied_drift > e.drift_budget) {
    e.verification.reason = fmt::format(
        "rejected: the loop moves the query {:.2f} m from the estimate, more than the "
        "drift budget {:.2f} m over {:.1f} m of path ({})",
        e.implied_drift, e.drift_budget, t_path.length, e.verification.reason);
  } else {
    e.verification.reason = fmt::format(
        "rejected: the loop turns the query {:.1f} deg from the estimate, more than the "
        "rotation budget {:.1f} deg over {:.1f} m of path ({})",
        e.implied_rotation * 180 / std::numbers::pi, e.rotation_budget * 180 / std::numbers::pi, r_path.length,
        e.verification.reason);
  }
}

void LoopClosure::setVisualYawPrior(VisualYawPrior prior) { impl_->visual_prior = std::move(prior); }

void LoopClosure::retire(std::size_t index, std::size_t by) {
  Impl& m = *impl_;
  if (by >= m.times.size() || index >= by)
    throw std::invalid_argument(
        fmt::format("loop closure: cannot retire keyframe {} for keyframe {} of {}", index, by, m.times.size()));
  if (m.config.enabled) m.database.remove(static_cast<int>(index));
  ++m.stats.retired;
  if (m.config.keep_retired_nodes || m.merged[index].into >= 0) return;
  // Only where a loop has tied the two passes together is their estimated relative pose worth freezing: the odometry
  // alone may have drifted tens of metres by then (farm course: 56 m before its first loop), and a pass that merely
  // crosses the estimate of another would be bolted to the wrong place (one pass: APE 3.6 -> 24.8 m).
  if (!m.loopBetween(index, by)) {
    ++m.stats.unmerged;
    return;
  }
  // `by` may itself have been merged (a retired keyframe can still stand for an older place): its node's owner.
  std::size_t into = by;
  while (m.merged[into].into >= 0) into = static_cast<std::size_t>(m.merged[into].into);
  // Merged, not held fixed: a frozen first pass could not follow the loops a later pass closes (kitti05-replay
  // APE 0.42 -> 0.71 m); merged, it moves with the pass that stands for it.
  const Eigen::Isometry3d T_into_kf =
      m.graph.pose(static_cast<int>(into)).inverse() * m.graph.pose(static_cast<int>(index));
  m.graph.mergeNode(static_cast<int>(index), static_cast<int>(into));
  m.merged[index] = {static_cast<long long>(into), Eigen::Quaterniond(T_into_kf.linear()).normalized(),
                     T_into_kf.translation()};
  ++m.stats.merged;
}

std::size_t LoopClosure::graphNodes() const { return impl_->graph.size(); }

std::size_t LoopClosure::descriptorBytes() const { return impl_->database.descriptorBytes(); }

std::vector<Eigen::Isometry3d> LoopClosure::poses() const {
  const std::size_t n = impl_->times.size();
  std::vector<Eigen::Isometry3d> out(n, Eigen::Isometry3d::Identity());
  // Newest first: a merged keyframe's owner is newer, so its pose is already there.
  for (std::size_t i = n; i-- > 0;) {
    const Impl::Merged& m = impl_->merged[i];
    if (m.into < 0) {
      out[i] = impl_->graph.pose(static_cast<int>(i));
      continue;
    }
    Eigen::Isometry3d T_into_kf = Eigen::Isometry3d::Identity();
    T_into_kf.linear() = m.q_into_kf.toRotationMatrix();
    T_into_kf.translation() = m.p_into_kf;
    out[i] = out[static_cast<std::size_t>(m.into)] * T_into_kf;
  }
  return out;
}

bool LoopClosure::searched(std::size_t index) const { return index < impl_->searched.size() && impl_->searched[index]; }

const std::vector<LoopEvent>& LoopClosure::events() const { return impl_->events; }
std::size_t LoopClosure::eventsDropped() const { return impl_->events_dropped; }
const LoopStats& LoopClosure::stats() const { return impl_->stats; }
const LoopClosureConfig& LoopClosure::config() const { return impl_->config; }

}  // namespace drover::pipeline
