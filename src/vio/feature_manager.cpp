#include "vio/feature_manager.hpp"

#include <Eigen/SVD>
#include <algorithm>

namespace drover::vio {

double FeatureManager::addFrame(int frame, const std::vector<FrameFeature>& features, double td) {
  last_tracked_ = 0;
  for (const FrameFeature& in : features) {
    Observation o{frame, in.normalized, in.velocity, td, in.lidar_depth, in.depth_spread};
    auto it = features_.find(in.id);
    if (it == features_.end()) {
      Feature f;
      f.id = in.id;
      f.obs.push_back(o);
      features_.emplace(in.id, std::move(f));
    } else {
      it->second.obs.push_back(o);
      ++last_tracked_;
    }
  }
  if (frame < 2) return -1;
  // VINS-Mono compensatedParallax2: the distance between the observations in frames frame-2 and frame-1.
  double sum = 0;
  int count = 0;
  for (const auto& [id, f] : features_) {
    const Observation* a = nullptr;
    const Observation* b = nullptr;
    for (const Observation& o : f.obs) {
      if (o.frame == frame - 2) a = &o;
      if (o.frame == frame - 1) b = &o;
    }
    if (a == nullptr || b == nullptr) continue;
    sum += (a->normalized - b->normalized).norm();
    ++count;
  }
  return count == 0 ? -1 : sum / count;
}

bool FeatureManager::usable(const Feature& f, int newest, int min_obs) const {
  return static_cast<int>(f.obs.size()) >= min_obs && f.start() < newest - 1;
}

namespace {

constexpr double kMinDepth = 0.1;    // [m]
constexpr double kMaxDepth = 200.0;  // [m]

Eigen::Vector3d bearing(const Observation& o) { return {o.normalized.x(), o.normalized.y(), 1.0}; }

// Linear triangulation (DLT, Hartley & Zisserman Sec. 12.2) of a point in the anchor camera from all observations:
// each view contributes two rows of x (P3 X) - P1 X = 0 with P the 3x4 [R|t] of anchor -> view.
double triangulateDepth(const Feature& f, const std::vector<Eigen::Isometry3d>& T_world_cam) {
  if (f.obs.size() < 2) return 0;
  const Eigen::Isometry3d& T_w_a = T_world_cam[static_cast<std::size_t>(f.start())];
  Eigen::MatrixXd A(2 * f.obs.size(), 4);
  int row = 0;
  for (const Observation& o : f.obs) {
    const Eigen::Isometry3d T_view_anchor = T_world_cam[static_cast<std::size_t>(o.frame)].inverse() * T_w_a;
    Eigen::Matrix<double, 3, 4> P;
    P << T_view_anchor.rotation(), T_view_anchor.translation();
    const Eigen::Vector3d b = bearing(o);  // (x, y, 1)
    A.row(row++) = b.x() * P.row(2) - P.row(0);
    A.row(row++) = b.y() * P.row(2) - P.row(1);
  }
  const Eigen::Vector4d X = Eigen::JacobiSVD<Eigen::MatrixXd>(A, Eigen::ComputeFullV).matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return 0;
  return X.z() / X.w();
}

}  // namespace

void FeatureManager::initializeDepths(const std::vector<Eigen::Isometry3d>& T_world_cam, bool use_lidar) {
  for (auto& [id, f] : features_) {
    const Observation& anchor = f.obs.front();
    if (use_lidar && anchor.lidar_depth > 0 && !f.lidar_anchor) {
      f.depth = anchor.lidar_depth;  // LVI-SAM: the lidar's depth replaces the triangulated one
      f.lidar_anchor = true;
      continue;
    }
    if (f.depth > 0) continue;
    const double d = triangulateDepth(f, T_world_cam);
    // VINS-Mono puts a depth below 0.1 m at its initial guess; here such a feature, or one too far for its baseline
    // to tell (a forward-moving camera's focus of expansion), waits for more parallax.
    f.depth = d > kMinDepth && d < kMaxDepth ? d : 0;
  }
}

void FeatureManager::removeFailures() {
  for (auto it = features_.begin(); it != features_.end();) {
    if (it->second.depth < 0) it = features_.erase(it);
    else ++it;
  }
}

void FeatureManager::removeObservation(std::uint64_t id, int frame) {
  auto it = features_.find(id);
  if (it == features_.end()) return;
  std::vector<Observation>& obs = it->second.obs;
  const bool anchor = !obs.empty() && obs.front().frame == frame;
  obs.erase(std::remove_if(obs.begin(), obs.end(), [frame](const Observation& o) { return o.frame == frame; }),
            obs.end());
  if (obs.empty()) {
    features_.erase(it);
  } else if (anchor) {  // a new anchor: the depth is re-triangulated or taken from its lidar
    it->second.depth = 0;
    it->second.lidar_anchor = false;
  }
}

void FeatureManager::removeOldest(const Eigen::Isometry3d& T_world_cam0, const Eigen::Isometry3d& T_world_cam1,
                                  bool use_lidar) {
  const Eigen::Isometry3d T_cam1_cam0 = T_world_cam1.inverse() * T_world_cam0;
  for (auto it = features_.begin(); it != features_.end();) {
    Feature& f = it->second;
    if (f.start() != 0) {
      for (Observation& o : f.obs) --o.frame;
      ++it;
      continue;
    }
    const Eigen::Vector3d p0 = anchorPoint(f, f.depth);
    const bool had_depth = f.depth > 0;
    f.obs.erase(f.obs.begin());
    if (f.obs.empty()) {
      it = features_.erase(it);
      continue;
    }
    for (Observation& o : f.obs) --o.frame;
    f.lidar_anchor = false;
    f.depth = 0;
    if (use_lidar && f.obs.front().lidar_depth > 0) {
      f.depth = f.obs.front().lidar_depth;
      f.lidar_anchor = true;
    } else if (had_depth && f.obs.front().frame == 0) {
      const double z = (T_cam1_cam0 * p0).z();
      f.depth = z > 0.1 ? z : 0;
    }
    ++it;
  }
}

void FeatureManager::removeSecondNewest(int newest) {
  for (auto it = features_.begin(); it != features_.end();) {
    Feature& f = it->second;
    std::vector<Observation>& obs = f.obs;
    const bool anchor = obs.front().frame == newest - 1;
    obs.erase(std::remove_if(obs.begin(), obs.end(), [newest](const Observation& o) { return o.frame == newest - 1; }),
              obs.end());
    if (obs.empty()) {
      it = features_.erase(it);
      continue;
    }
    for (Observation& o : obs)
      if (o.frame == newest) o.frame = newest - 1;
    if (anchor) {  // VINS removeFront: the feature now starts at the (re-indexed) newest frame, depth unsolved
      f.depth = 0;
      f.lidar_anchor = false;
    }
    ++it;
  }
}

void FeatureManager::clear() {
  features_.clear();
  last_tracked_ = 0;
}

}  // namespace drover::vio
