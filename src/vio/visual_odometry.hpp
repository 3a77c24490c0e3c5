#pragma once
// The VIS driven frame by frame in time order (the deterministic replay of `drover run`): the KLT front end
// (visual::FeatureTracker with the configured detector), LVI-SAM's lidar depth for the tracked features
// (visual::DepthAssociator over the LIS's recent deskewed sweeps), and the sliding-window estimator.
// The LIS plugs in through two callbacks: its IMU pose at a camera stamp (to put the lidar points into the camera)
// and its full state there (to seed the window). Without a lidar both are empty and the VIS runs alone.
#include <Eigen/Geometry>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/calibration.hpp"
#include "types/camera.hpp"
#include "visual/depth_association.hpp"
#include "visual/feature_tracker.hpp"
#include "vio/sliding_window.hpp"

namespace drover::vio {

struct VisConfig {
  VioConfig vio;
  visual::FeatureTrackerConfig tracker;
  visual::DepthAssociationConfig depth;
};

struct VisStageMs {  // [ms] wall time per stage of one frame
  double track = 0, depth = 0, solve = 0, marginalize = 0, covariance = 0, total = 0;
};

struct VisFrame {
  FrameResult estimate;
  int front_tracked = 0;     // features the front end carried from the previous frame
  int front_added = 0;       // new features from the detector and the corner top-up
  int front_added_corners = 0;  // of which from the corner top-up
  int depth_associated = 0;  // features with a lidar depth this frame
  bool detected = false;     // the detector ran on this frame
  double share_three = 0;    // of the window's solved features, the share seen in >= 3 window frames
  VisStageMs ms;
};

class VisualOdometry {
 public:
  using PoseAt = std::function<std::optional<Eigen::Isometry3d>(Time)>;  // T_world_imu of the LIS at t
  // Throws std::invalid_argument on an invalid config or calibration, or a null detector.
  VisualOdometry(const VisConfig& config, const Calibration& calibration, const imu::PreintegrationConfig& imu_config,
                 std::shared_ptr<visual::KeypointDetector> detector);
  ~VisualOdometry();

  void addImu(const ImuSample& sample);
  // A deskewed sweep from the LIS: its points in the lidar frame at its start t, and the lidar's pose there.
  void addSweep(Time t, const Eigen::Isometry3d& T_world_lidar, const std::vector<Eigen::Vector3f>& points_lidar);
  // The LIS's world moved (a loop correction, T_new_old): the buffered sweeps follow, so that the lidar depth of
  // the next frames pairs the corrected LIS poses with points in the same frame. The window's own states stay in
  // the frame it started in (the VIS is an odometry).
  void onWorldCorrected(const Eigen::Isometry3d& T_new_old) { depth_.reanchor(T_new_old); }
  // One camera frame. Throws std::invalid_argument on an image of the wrong size or type (the caller warns and
  // skips it).
  VisFrame addFrame(const CameraFrame& frame, const PoseAt& lis_pose, const Seeder& seed);
  // addFrame in two steps, so that the front end can run ahead in another thread: track() touches only the KLT
  // tracker, addTracked() everything else, so one thread may track frame k+1 while another adds frame k. Frames must
  // be tracked in time order, and each added with its own tracks (frame_t: CameraFrame::t; a mismatch throws
  // std::invalid_argument). addFrame(f) is addTracked(f.t, track(f)).
  visual::TrackingResult track(const CameraFrame& frame);
  VisFrame addTracked(Time frame_t, const visual::TrackingResult& tracks, const PoseAt& lis_pose, const Seeder& seed);
  const SlidingWindowEstimator& estimator() const { return estimator_; }
  // The LIS asks the VIS to start again (its gates refused it too long, pipeline::VisualWatch): the window is
  // cleared and re-initialises from the LIS's state at the next frames; the tracker's features carry on.
  void reset() { estimator_.reset(); }
  void setRealtime(bool realtime) { estimator_.setRealtime(realtime); }

 private:
  VisConfig config_;
  Calibration calibration_;
  visual::CameraModel camera_;
  visual::FeatureTracker tracker_;
  visual::DepthAssociator depth_;
  SlidingWindowEstimator estimator_;
  Time last_sweep_t_ = 0;
};

}  // namespace drover::vio
