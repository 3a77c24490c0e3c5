#pragma once
// The VIS inside `drover run`: feeds vio::VisualOdometry with the dataset's IMU and camera frames and, when the
// LIS runs, with its deskewed sweeps (lidar depth) and its states (initialisation); streams the VIS trajectory and
// the per-frame records to trajectory_vis.tum and vis_frames.jsonl as they come (an hour at 15 Hz kept in memory was
// 15 MB, and report.json's per-frame array 21 MB more at the end), and keeps counts and sums for report.json's "vis".
#include <nlohmann/json.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/drover/run_preset.hpp"
#include "apps/drover/run_record.hpp"
#include "apps/drover/track_ahead.hpp"
#include "io/reader.hpp"
#include "pipeline/lidar_odometry.hpp"
#include "vio/visual_odometry.hpp"

namespace drover::cli {

// Sums over the recorded frames, for report.json's means.
struct VisFrameSums {
  std::size_t frames = 0, keyframes = 0, keyframes_by_time = 0, detected = 0, topped_up = 0, corners = 0;
  double tracked = 0, with_depth = 0, on_ground = 0, share_three = 0;
  vio::VisStageMs ms;
  void add(const vio::VisFrame& f);
};

// The VIS's configuration and detector from a platform config.
struct VisSetup {
  vio::VisConfig config;
  std::shared_ptr<visual::KeypointDetector> detector;
  std::string detector_name;
};
// Reads the `visual:` and `vio:` sections (defaults without a config). SuperPoint whose weights cannot be loaded
// falls back to Shi-Tomasi with a warning.
// A preset (run_preset.hpp) overrides the methods the config chose. A relative weights path is the working
// directory's, else the one beside the config file, else, when base_dir is given, base_dir's (drover_ros's
// ~working_dir: roslaunch starts a node in ROS_HOME, where the shipped configs' path finds nothing).
VisSetup loadVisSetup(const std::string& config_path, const MethodChoice& method = {}, const std::string& base_dir = {});

class RunVis {
 public:
  // The replay: runs its own vio::VisualOdometry (onImu, onFrame, onSweep, onLisState).
  RunVis(const std::string& config_path, const Calibration& calibration, const imu::PreintegrationConfig& imu,
         const MethodChoice& method = {});
  RunVis(const VisSetup& setup, const Calibration& calibration, const imu::PreintegrationConfig& imu);
  // --realtime: the VisualOdometry runs in pipeline::System; record() each frame it took, and attach() it (after
  // the System's shutdown) for the report.
  explicit RunVis(const VisSetup& setup);
  ~RunVis();
  void record(const vio::VisFrame& frame);
  // Where the per-frame lines and the trajectory (T_world_imu * T_imu_body, trajectory.tum's body frame) go; each
  // file is opened at its first line, so a run without camera frames writes neither. Without this call the lines
  // and poses are counted, not kept. Throws IoError on a failed write.
  void streamTo(const std::string& frames_path, const std::string& trajectory_path,
                const Eigen::Isometry3d& T_imu_body);
  // Both files flushed and closed; the trajectory's count and span (no poses: no file).
  ImuRateFile::Summary finishFiles();
  void attach(const vio::VisualOdometry* vo, std::size_t frames_in, std::size_t frames_bad);

  void onImu(const ImuSample& sample);
  // A camera frame; lis is the LIS when it runs (nullptr with --no-lidar). A bad image is a counted warning.
  // With `ahead`, the frame's tracks come from it (the frame was submitted there; track_ahead.hpp).
  void onFrame(const CameraFrame& frame, const pipeline::LidarOdometry* lis, TrackAhead* ahead = nullptr);
  // Every sweep the LIS processed (registered with LidarOdometry::setSweepListener).
  void onSweep(Time t, const Eigen::Isometry3d& T_world_lidar, const std::vector<Eigen::Vector3f>& points_lidar);
  // The newest LIS sweep with a fused IMU state (its velocity and biases seed the VIS), and the LIS's request to
  // reset the VIS (ScanOutcome::vis_reset), which is done and recorded as an event.
  void onLisState(const pipeline::ScanOutcome& outcome);

  // The VIS's state after the newest frame, once (for the LIS's VIS fusion, LidarOdometry::addVisualState);
  // nothing when that frame had no estimate or it was taken.
  std::optional<pipeline::VisualState> takeState();

  std::size_t framesEstimated() const { return estimated_; }  // frames with a pose (initialised)
  const std::string& detectorName() const { return detector_name_; }
  // report.json's "vis" section (without the APE, which the caller adds): counts, events, means.
  nlohmann::json report() const;
  std::size_t framesIn() const { return frames_in_; }
  const std::string& waitingReason() const { return waiting_; }  // why the VIS has not initialised (the newest)

 private:
  std::optional<vio::SeedState> seedAt(Time t, const pipeline::LidarOdometry& lis) const;
  void noteReset(Time t, const std::string& why);
  void noteWaiting(const vio::FrameResult& r);  // a frame after a reset: a long wait reported, and its end

  std::unique_ptr<vio::VisualOdometry> own_;
  const vio::VisualOdometry* vo_ = nullptr;  // own_, or the System's
  std::string detector_name_;
  vio::VioConfig vio_config_;
  visual::FeatureTrackerConfig tracker_;  // after the preset
  std::string trajectory_path_;
  Eigen::Isometry3d T_imu_body_ = Eigen::Isometry3d::Identity();
  std::unique_ptr<ImuRateFile> trajectory_;  // opened at the first pose
  std::size_t estimated_ = 0;
  std::string frames_path_;
  JsonLines frames_{"camera frame"};  // opened at the first frame
  VisFrameSums sums_;
  struct Event {
    Time t;
    std::string kind, what;
  };
  std::vector<Event> events_;        // initialisations and resets (and the last "waiting" reason)
  std::string waiting_;              // why the VIS has not initialised yet (the newest reason)
  // After a reset: since when the VIS has waited to initialise again, and whether that wait was reported yet.
  std::optional<Time> waiting_since_;
  bool waiting_reported_ = false;
  std::optional<pipeline::ScanOutcome> lis_state_;
  std::size_t frames_in_ = 0, frames_bad_ = 0, resets_ = 0, rescales_ = 0, coasted_ = 0;
  bool coasting_ = false;  // the previous frame coasted (vio::FrameResult::coasting)
  std::optional<Time> first_init_;
  pipeline::VisualStateStream states_;
  std::optional<pipeline::VisualState> new_state_;
};

}  // namespace drover::cli
