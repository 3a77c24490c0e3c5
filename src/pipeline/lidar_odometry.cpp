#include "pipeline/lidar_odometry.hpp"

#include <fmt/format.h>

#include <limits>
#include <stdexcept>

#include "pipeline/lidar_odometry_impl.hpp"

namespace drover::pipeline {

LidarOdometry::LidarOdometry(const OdometryConfig& config, const Calibration& calibration) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("odometry config: " + e);
  impl_ = std::make_unique<Impl>(config, calibration);
}

LidarOdometry::~LidarOdometry() = default;

std::vector<ScanOutcome> LidarOdometry::process(const Measurement& m) {
  if (const auto* imu = std::get_if<ImuSample>(&m)) {
    if (!impl_->config.use_imu) return impl_->drain(false);
    impl_->onImu(*imu);
    std::vector<ScanOutcome> done = impl_->drain(false);
    // After the drain, so that a sweep this sample completed is already fused into the published state.
    const Time last = impl_->imu_rate.empty() ? std::numeric_limits<Time>::min() : impl_->imu_rate.back().t;
    if (imu->t > last)
      if (const std::optional<Eigen::Isometry3d> T = impl_->fusion.propagatedImuPose(imu->t)) {
        std::deque<StampedPose>& kept = impl_->imu_rate;
        kept.push_back({imu->t, *T});
        while (kept.back().t - kept.front().t > kImuRateKept) kept.pop_front();  // an hour would be ~100 MB
        if (impl_->imu_rate_listener) impl_->imu_rate_listener(kept.back());
      }
    return done;
  }
  if (const auto* scan = std::get_if<LidarScan>(&m)) return impl_->onScan(*scan);
  return {};  // camera frames belong to the VIS
}

std::vector<ScanOutcome> LidarOdometry::finish() { return impl_->drain(true); }

Trajectory LidarOdometry::trajectory() const {
  Trajectory out;
  out.reserve(impl_->anchors.size());
  for (const Impl::Anchor& a : impl_->anchors) {
    Eigen::Isometry3d T_kf_sweep = Eigen::Isometry3d::Identity();
    T_kf_sweep.linear() = a.q_kf_sweep.cast<double>().normalized().toRotationMatrix();
    T_kf_sweep.translation() = a.p_kf_sweep.cast<double>();
    out.push_back({a.t, impl_->map.keyframe(a.keyframe).T_world_lidar * T_kf_sweep});
  }
  return out;
}

const std::deque<StampedPose>& LidarOdometry::recentImuRate() const { return impl_->imu_rate; }

void LidarOdometry::setImuRateListener(ImuRateListener listener) { impl_->imu_rate_listener = std::move(listener); }

std::size_t LidarOdometry::keyframeBytes() const {
  std::size_t bytes = 0;
  for (std::size_t i = 0; i < impl_->map.size(); ++i) bytes += lidar::featureBytes(impl_->map.keyframe(i).features());
  return bytes;
}

const lidar::LocalMap& LidarOdometry::keyframeMap() const { return impl_->map; }

Trajectory LidarOdometry::keyframeTrajectory() const {
  Trajectory out;
  for (std::size_t i = 0; i < impl_->map.size(); ++i)
    out.push_back({impl_->map.keyframe(i).t, impl_->map.keyframe(i).T_world_lidar});
  return out;
}

void LidarOdometry::setSweepListener(SweepListener listener) { impl_->sweep_listener = std::move(listener); }

void LidarOdometry::addVisualState(const VisualState& state) {
  impl_->fusion.addVisualState(state);
  if (impl_->config.loop.visual_yaw_prior && !impl_->external_loops) impl_->visual_yaw.add(state);
}

void LidarOdometry::setKeyframeListener(KeyframeListener listener, bool external_loops) {
  impl_->keyframe_listener = std::move(listener);
  impl_->external_loops = external_loops;
}

Eigen::Isometry3d LidarOdometry::applyLoopCorrection(const LoopCorrection& c) {
  Impl& m = *impl_;
  if (c.poses.empty() || c.poses.size() > m.map.size())
    throw std::invalid_argument(fmt::format("loop correction for {} keyframes, the map has {}", c.poses.size(),
                                            m.map.size()));
  // Keyframes made after the query (the loop was found while the LIS went on) move rigidly with it.
  const std::size_t q = c.poses.size() - 1;
  const Eigen::Isometry3d T_new_old_query = c.poses[q] * m.map.keyframe(q).T_world_lidar.inverse();
  std::vector<Eigen::Isometry3d> poses = c.poses;
  for (std::size_t i = q + 1; i < m.map.size(); ++i) poses.push_back(T_new_old_query * m.map.keyframe(i).T_world_lidar);
  const Eigen::Isometry3d T_new_old = m.correctKeyframes(poses);
  m.fusion.reanchor(T_new_old);
  m.stats.loop_times.push_back(c.event.t_query);
  return T_new_old;
}

bool LidarOdometry::prepareMap() {
  Impl& m = *impl_;
  if (!m.prebuild_center || m.map.size() <= m.map_first_keyframe) return false;
  m.map.build(*m.prebuild_center, m.map_first_keyframe);
  m.prebuild_center.reset();
  return true;
}

std::optional<imu::FusedState> LidarOdometry::fusedImuState() const { return impl_->fusion.fusedState(); }

lidar::PointCloud LidarOdometry::mapCloud(float leaf) const {
  std::vector<std::size_t> all(impl_->map.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  return impl_->map.fullCloudWorld(all, leaf);
}

const OdometryStats& LidarOdometry::stats() const {
  impl_->stats.imu = impl_->fusion.imuStats();
  return impl_->stats;
}

const OdometryConfig& LidarOdometry::config() const { return impl_->config; }

const LoopClosure& LidarOdometry::loopClosure() const { return impl_->loops; }

}  // namespace drover::pipeline
