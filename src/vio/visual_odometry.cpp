#include "vio/visual_odometry.hpp"

#include <chrono>
#include <stdexcept>

namespace drover::vio {
namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
}  // namespace

VisualOdometry::VisualOdometry(const VisConfig& config, const Calibration& calibration,
                               const imu::PreintegrationConfig& imu_config,
                               std::shared_ptr<visual::KeypointDetector> detector)
    : config_(config),
      calibration_(calibration),
      camera_(calibration.camera),
      tracker_(camera_, std::move(detector), config.tracker),
      depth_(config.depth),
      estimator_(config.vio, imu_config, calibration.T_imu_cam, calibration.camera.fx) {}

VisualOdometry::~VisualOdometry() = default;

void VisualOdometry::addImu(const ImuSample& sample) { estimator_.addImu(sample); }

void VisualOdometry::addSweep(Time t, const Eigen::Isometry3d& T_world_lidar,
                              const std::vector<Eigen::Vector3f>& points_lidar) {
  if (config_.vio.depth_mode == DepthMode::kOff) return;
  if (depth_.sweepCount() > 0 && t <= last_sweep_t_) return;
  last_sweep_t_ = t;
  std::vector<Eigen::Vector3d> world;
  world.reserve(points_lidar.size());
  for (const Eigen::Vector3f& p : points_lidar) world.push_back(T_world_lidar * p.cast<double>());
  depth_.addSweep(t, world);
}

VisFrame VisualOdometry::addFrame(const CameraFrame& frame, const PoseAt& lis_pose, const Seeder& seed) {
  return addTracked(frame.t, track(frame), lis_pose, seed);
}

visual::TrackingResult VisualOdometry::track(const CameraFrame& frame) {
  return tracker_.track(frame.t + calibration_.camera_time_offset, visual::imageView(frame.image));
}

VisFrame VisualOdometry::addTracked(Time frame_t, const visual::TrackingResult& tracks, const PoseAt& lis_pose,
                                    const Seeder& seed) {
  VisFrame out;
  const auto t0 = Clock::now();
  const Time t = frame_t + calibration_.camera_time_offset;
  if (tracks.t != t)
    throw std::invalid_argument("VisualOdometry::addTracked: tracks of " + std::to_string(tracks.t) +
                                " ns for the frame at " + std::to_string(t) + " ns");
  out.ms.track = tracks.ms;
  out.front_tracked = tracks.tracked;
  out.front_added = tracks.added;
  out.front_added_corners = tracks.added_corners;
  out.detected = tracks.added > tracks.added_corners;  // the detector's own points

  std::vector<FrameFeature> features(tracks.features.size());
  for (std::size_t k = 0; k < tracks.features.size(); ++k) {
    features[k].id = tracks.features[k].id;
    features[k].normalized = tracks.features[k].normalized;
    features[k].velocity = tracks.features[k].velocity;
  }
  const auto t1 = Clock::now();
  if (config_.vio.depth_mode != DepthMode::kOff && depth_.sweepCount() > 0 && lis_pose) {
    if (const std::optional<Eigen::Isometry3d> T_wi = lis_pose(t)) {
      std::vector<Eigen::Vector2d> normalized;
      for (const FrameFeature& f : features) normalized.push_back(f.normalized);
      const visual::DepthAssociationResult d = depth_.associate(t, *T_wi * calibration_.T_imu_cam, normalized);
      for (std::size_t k = 0; k < features.size(); ++k) {
        if (d.features[k].status != visual::DepthStatus::kOk) continue;
        features[k].lidar_depth = d.features[k].depth;
        features[k].depth_spread = d.features[k].spread;
      }
      out.depth_associated = d.associated;
    }
  }
  out.ms.depth = msSince(t1);
  out.estimate = estimator_.addFrame(t, features, seed);
  out.ms.solve = out.estimate.ms_solve;
  out.ms.marginalize = out.estimate.ms_marginalize;
  out.ms.covariance = out.estimate.ms_covariance;
  out.share_three = estimator_.featuresInThreeOrMore();
  out.ms.total = tracks.ms + msSince(t0);
  return out;
}

}  // namespace drover::vio
