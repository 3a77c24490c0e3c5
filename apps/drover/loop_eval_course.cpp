// drover loop eval, mode A: place recognition along a course against its ground truth. A keyframe is kept every
// keyframe_distance metres of ground-truth travel; each is queried against the database of the earlier ones (the
// database excludes its exclude_recent newest entries, and candidates younger than loop.min_age are passed over, as
// in LoopClosure) before being added. No ICP: this measures the descriptor, the ring-key retrieval and the shift
// search alone.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "apps/drover/loop_eval.hpp"
#include "geometry/so3.hpp"
#include "io/config.hpp"
#include "io/dataset.hpp"
#include "loop/scan_context_database.hpp"

namespace drover::cli {
namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// Ground-truth lidar pose at t: the nearest ground-truth pose (simulator: 200 Hz; KITTI: one per scan) times the
// lidar's pose on the body; nothing when the nearest is more than 50 ms away.
class Truth {
 public:
  Truth(const io::GroundTruth& gt, const Calibration& calibration, const std::string& dataset) : poses_(gt.poses) {
    if (gt.poses.empty()) throw std::invalid_argument("dataset " + dataset + " has no ground truth");
    if (gt.body_frame == "imu")
      T_body_lidar_ = calibration.T_imu_lidar;
    else if (gt.body_frame != "lidar")
      throw std::invalid_argument("dataset " + dataset + ": ground truth of frame '" + gt.body_frame +
                                  "' is not supported (imu or lidar)");
  }
  std::optional<Eigen::Isometry3d> lidarAt(Time t) const {
    auto it = std::lower_bound(poses_.begin(), poses_.end(), t, [](const StampedPose& p, Time v) { return p.t < v; });
    if (it == poses_.end() || (it != poses_.begin() && t - std::prev(it)->t < it->t - t)) --it;
    if (std::abs(it->t - t) > 50'000'000) return std::nullopt;
    return it->T_world_body * T_body_lidar_;
  }

 private:
  const Trajectory& poses_;
  Eigen::Isometry3d T_body_lidar_ = Eigen::Isometry3d::Identity();
};

class CourseEvaluator {
 public:
  CourseEvaluator(const LoopEvalOptions& o, const pipeline::OdometryConfig& config)
      : config_(config), sc_(config.loop.database.descriptor), database_(config.loop.database) {
    truth_.true_distance = o.true_distance;
    truth_.correct_distance = 2 * o.true_distance;
    truth_.exclude_recent = config.loop.database.exclude_recent;
    truth_.min_age = config.loop.min_age;
    if (std::string e = truth_.validate(); !e.empty()) throw std::invalid_argument(e);
  }

  void addKeyframe(LidarScan&& scan, const Eigen::Isometry3d& T_world_lidar) {
    ++data_.keyframes;
    const Time t = scan.t;
    lidar::PointCloud cloud;
    try {
      cloud = descriptorCloud(std::move(scan), config_);
    } catch (const std::invalid_argument& e) {
      ++data_.skipped;
      spdlog::warn("keyframe at {:.3f} s skipped: {}", toSeconds(t), e.what());
      return;
    }
    auto t0 = Clock::now();
    const loop::AugmentedScanContext query = loop::makeAugmentedScanContext(cloud, sc_);
    data_.descriptor_ms += msSince(t0);
    const std::size_t index = times_.size();
    times_.push_back(t);
    poses_.push_back(T_world_lidar);
    positions_.push_back(T_world_lidar.translation());
    t0 = Clock::now();
    const loop::DatabaseQuery q = database_.query(query);
    data_.query_ms += msSince(t0);
    score(index, query, q);
    database_.add(static_cast<int>(index), query.descriptors[0]);
    if ((index + 1) % 500 == 0) spdlog::info("{} keyframes at {:.1f} s", index + 1, toSeconds(t));
  }

  LoopEvalData finish() {
    const double described = static_cast<double>(times_.size());
    if (described > 0) {
      data_.descriptor_ms /= described;
      data_.query_ms /= described;
    }
    return std::move(data_);
  }

 private:
  void score(std::size_t index, const loop::AugmentedScanContext& query, const loop::DatabaseQuery& q) {
    const Time newest = times_[index] - fromSeconds(truth_.min_age);
    const loop::LoopCandidate* best = nullptr;  // candidates are sorted best first
    for (const loop::LoopCandidate& c : q.candidates)
      if (times_[static_cast<std::size_t>(c.id)] <= newest) {
        best = &c;
        break;
      }
    const loop::TruthMatch m = loop::matchAgainstTruth(positions_, times_, index, best ? best->id : -1, truth_);
    loop::PlaceQuery pq{best != nullptr, best ? best->match.match.distance : 1.0, m.candidate_correct,
                        m.has_true_revisit};
    data_.queries.push_back(pq);
    if (!pq.has_candidate || pq.distance >= sc_.threshold) return;
    if (!pq.candidate_correct) {
      data_.false_positives.push_back(
          {times_[index], times_[static_cast<std::size_t>(best->id)], pq.distance, m.candidate_distance});
      return;
    }
    // A detected right place: would the prior-narrowed search (ground-truth relative yaw) find the same shift?
    const std::size_t id = static_cast<std::size_t>(best->id);
    const double yaw = geometry::yawOf(poses_[id].linear().transpose() * poses_[index].linear());
    const loop::ShiftMatch narrowed = loop::narrowedShiftSearch(
        database_.descriptor(best->id), query.descriptors[static_cast<std::size_t>(best->match.index)], yaw, sc_);
    ++data_.narrowed_checked;
    if (narrowed.shift == best->match.match.shift) ++data_.narrowed_equal;
  }

  const pipeline::OdometryConfig& config_;
  const loop::ScanContextConfig& sc_;
  loop::ScanContextDatabase database_;
  loop::TruthConfig truth_;
  std::vector<Time> times_;
  std::vector<Eigen::Isometry3d> poses_;
  std::vector<Eigen::Vector3d> positions_;
  LoopEvalData data_;
};

}  // namespace

LoopEvalData evaluateCourse(const LoopEvalOptions& o, const pipeline::OdometryConfig& config) {
  if (!std::filesystem::exists(o.dataset)) throw std::invalid_argument("dataset " + o.dataset + " not found");
  if (!std::isfinite(o.keyframe_distance) || o.keyframe_distance <= 0)
    throw std::invalid_argument(fmt::format("--keyframe-distance must be > 0 m, got {}", o.keyframe_distance));
  io::DatasetOptions options = o.config.empty() ? io::DatasetOptions{} : io::loadDatasetOptions(o.config);
  options.load_images = false;
  options.load_imu = false;
  options.kitti_max_frames = o.max_frames;
  const std::unique_ptr<io::Reader> reader = io::openDataset(o.dataset, o.format, options);
  const Truth truth(reader->groundTruth(), reader->calibration(), o.dataset);
  CourseEvaluator evaluator(o, config);
  std::optional<Eigen::Vector3d> previous;  // the last scan's ground-truth position
  double travelled = 0;                     // [m] since the last keyframe
  std::size_t scans = 0;
  while (std::optional<Measurement> m = reader->next()) {
    auto* scan = std::get_if<LidarScan>(&*m);
    if (!scan) continue;
    if (o.max_frames > 0 && scans >= o.max_frames) break;
    ++scans;
    const std::optional<Eigen::Isometry3d> T = truth.lidarAt(scan->t);
    if (!T) continue;
    if (previous) travelled += (T->translation() - *previous).norm();
    const bool first = !previous;
    previous = T->translation();
    if (!first && travelled < o.keyframe_distance) continue;
    travelled = 0;
    evaluator.addKeyframe(std::move(*scan), *T);
  }
  for (const std::string& notice : reader->drops().notices) spdlog::warn("{}", notice);
  LoopEvalData d = evaluator.finish();
  d.scans = scans;
  return d;
}

}  // namespace drover::cli
