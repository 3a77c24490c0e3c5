#pragma once
// LidarOdometry's internals (src/pipeline/lidar_odometry.cpp: the interface and loop corrections;
// lidar_odometry_sweep.cpp: the per-sweep chain). Only those two files include it.
#include <deque>
#include <optional>

#include "lidar/deskew.hpp"
#include "lidar/voxel_filter.hpp"
#include "pipeline/imu_fusion.hpp"
#include "pipeline/imu_stream_notices.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "pipeline/visual_yaw_history.hpp"

namespace drover::pipeline {

struct LidarOdometry::Impl {
  OdometryConfig config;
  Calibration calibration;
  lidar::Deskewer deskewer;
  lidar::FeatureExtractor extractor;
  lidar::LocalMap map;
  lidar::ScanMatcher matcher;
  lidar::KeyframePolicy policy;
  ImuFusion fusion;
  ImuStreamNotices imu_notices;
  std::optional<Time> last_imu;   // [ns] stamp of the newest accepted IMU sample
  std::deque<LidarScan> pending;  // sweeps waiting for the IMU to cover their end (time order)
  Trajectory recent;              // T_world_lidar of the last two processed sweeps (motion model, IMU restart)
  std::deque<StampedPose> imu_rate;  // T_world_imu per IMU sample after initialisation, the last kImuRateKept
  ImuRateListener imu_rate_listener;  // every one of them (setImuRateListener)
  Eigen::Isometry3d T_world_lastkf = Eigen::Isometry3d::Identity();
  OdometryStats stats;
  LoopClosure loops;
  VisualYawHistory visual_yaw;  // the VIS's attitude: loop closure's shift prior (config.loop.visual_yaw_prior)
  // Per processed sweep: the keyframe it followed and its pose relative to it, so a loop correction of the
  // keyframes carries every sweep with it and the trajectory is the keyframes' poses times these. Compact (48 bytes,
  // not a world pose and an anchor's 272): an hour of sweeps at 10 Hz is 1.7 MB. Floats: the offset from a keyframe
  // is metres, so single precision costs under a micrometre; the motion model keeps its exact copy
  // (recent_kf_sweep). A deque, not a vector: an hour's vector doubles to twice what it holds and copies itself each
  // time, where a deque adds a block at a time.
  struct Anchor {
    Time t = 0;
    std::uint32_t keyframe = 0;
    Eigen::Quaternionf q_kf_sweep = Eigen::Quaternionf::Identity();
    Eigen::Vector3f p_kf_sweep = Eigen::Vector3f::Zero();
  };
  std::deque<Anchor> anchors;
  std::vector<Eigen::Isometry3d> recent_kf_sweep;  // the anchors of `recent`, exact
  geometry::Matrix6d degenerate_since_kf = geometry::Matrix6d::Zero();  // sum of d d^T since the last keyframe
  int degenerate_run = 0;               // consecutive degenerate sweeps
  std::size_t map_first_keyframe = 0;   // the local map uses keyframes from this index on (submap start)
  std::size_t retire_next = 0;          // the next keyframe to retire the keyframes it supersedes (when old enough)
  SweepListener sweep_listener;         // the VIS's lidar depth (setSweepListener)
  KeyframeListener keyframe_listener;   // live: loop closure elsewhere, map updates (setKeyframeListener)
  bool external_loops = false;
  // Where the map changed (a keyframe added, a loop correction): prepareMap() builds the local map around it.
  std::optional<Eigen::Vector3d> prebuild_center;

  Impl(const OdometryConfig& c, const Calibration& calib)
      : config(c),
        calibration(calib),
        deskewer(lidar::DeskewerConfig{}),
        extractor(c.features),
        map(c.local_map),
        matcher(c.matcher),
        policy(c.keyframes),
        fusion(c, calib.T_imu_lidar),
        loops(c.loopClosure()),
        visual_yaw(calib.T_imu_lidar) {
    if (c.loop.visual_yaw_prior) loops.setVisualYawPrior(visual_yaw.prior());
  }

  std::vector<ScanOutcome> onScan(LidarScan scan);
  std::vector<ScanOutcome> drain(bool force);
  std::optional<ScanOutcome> processScan(LidarScan& scan);
  bool preprocess(LidarScan& scan, ScanOutcome& out);
  Eigen::Isometry3d guess(Time t, bool& from_imu, ScanOutcome& out) const;
  lidar::FeatureSet deskewAndExtract(const LidarScan& scan, const std::optional<lidar::SweepMotion>& motion,
                                     ScanOutcome& out) const;
  void match(const lidar::FeatureSet& features, const Eigen::Isometry3d& guess, ScanOutcome& out);
  void countMatch(ScanOutcome& out);
  void onImu(const ImuSample& sample) {
    const imu::SampleStatus status = fusion.addImu(sample);
    if (std::optional<std::string> line = imu_notices.onSample(sample, status, last_imu)) notice(std::move(*line));
    if (status == imu::SampleStatus::kAccepted || status == imu::SampleStatus::kAcceptedAfterGap) last_imu = sample.t;
  }
  void notice(std::string line) {
    if (stats.notices.size() < OdometryStats::kMaxNotices) stats.notices.push_back(std::move(line));
  }
  void keyframe(const lidar::FeatureSet& features, ScanOutcome& out);
  // (retired, superseded by), ascending in the retired one
  std::vector<std::pair<std::size_t, std::size_t>> supersededKeyframes();
  void accumulateDegeneracy(const ScanOutcome& out);
  void applyLoopCorrection(ScanOutcome& out);
  Eigen::Isometry3d correctKeyframes(const std::vector<Eigen::Isometry3d>& poses);
  void record(const ScanOutcome& out);
};

}  // namespace drover::pipeline
