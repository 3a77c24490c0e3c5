#include "apps/drover/run_vis.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "io/visual/visual_config_io.hpp"
#include "io/visual/vio_config_io.hpp"
#include "pipeline/lis_seed.hpp"

namespace drover::cli {
namespace {

using Json = nlohmann::json;

constexpr std::size_t kMaxEvents = 200;  // report.json keeps the first events; the counters count them all
constexpr std::size_t kShownResets = 20;  // reset warnings printed; the rest are counted

// A warning that -q (errors only) keeps: a run that quietly used another detector than the one asked for would be
// misread, and an [error] line would say the run failed (the CLI's contract), which it did not. Called at set-up,
// before any thread logs.
void warnEvenWhenQuiet(const std::string& message) {
  const spdlog::level::level_enum level = spdlog::get_level();
  if (level > spdlog::level::warn) spdlog::set_level(spdlog::level::warn);
  spdlog::warn("{}", message);
  spdlog::set_level(level);
}

// A line of vis_frames.jsonl: what the VIS made of one camera frame.
Json frameLine(const vio::VisFrame& f) {
  const vio::FrameResult& r = f.estimate;
  Json line = {{"t", toSeconds(r.t)},
               {"initialized", r.initialized},
               {"keyframe", r.keyframe},
               {"keyframe_by_time", r.keyframe_by_time},
               {"detected", f.detected},
               {"corners_added", f.front_added_corners},
               {"tracked", f.front_tracked},
               {"features", r.features},
               {"with_lidar_depth", r.with_lidar_depth},
               {"on_ground", r.on_ground},
               {"outliers", r.outliers},
               {"iterations", r.iterations},
               {"ms",
                {{"track", f.ms.track},
                 {"depth", f.ms.depth},
                 {"solve", f.ms.solve},
                 {"marginalize", f.ms.marginalize},
                 {"total", f.ms.total}}}};
  // The state behind the pose: a bias the window got wrong (a forward accelerometer bias at constant speed) shows in
  // the trajectory only once the vision fails and the speed drifts; here it shows before.
  if (r.initialized) {
    line["speed"] = r.v_world.norm();
    line["acc_bias"] = {r.bias.acc.x(), r.bias.acc.y(), r.bias.acc.z()};
    line["gyro_bias"] = {r.bias.gyro.x(), r.bias.gyro.y(), r.bias.gyro.z()};
  }
  return line;
}

}  // namespace

VisSetup loadVisSetup(const std::string& config_path, const MethodChoice& method, const std::string& base_dir) {
  const std::vector<std::string> also_look_in = base_dir.empty() ? std::vector<std::string>{}
                                                                 : std::vector<std::string>{base_dir};
  io::VisualConfig visual = config_path.empty() ? io::VisualConfig{} : io::loadVisualConfig(config_path, also_look_in);
  VisSetup setup;
  setup.config.vio = config_path.empty() ? vio::VioConfig{} : io::loadVioConfig(config_path);
  method.apply(visual, setup.config.vio);
  setup.config.tracker = visual.tracker;
  setup.config.depth = visual.depth;
  setup.detector_name = visual::detectorTypeName(visual.detector.type);
  try {
    setup.detector = visual::makeDetector(visual.detector);
  } catch (const std::invalid_argument& e) {
    // SuperPoint's weights are a separate download (non-commercial licence) and a relative path in a config is the
    // working directory's (else the one beside the config file): a run must not fail for them. Shi-Tomasi is
    // VINS-Mono's and LVI-SAM's own.
    if (visual.detector.type != visual::DetectorType::kSuperPoint) throw;
    const std::string what = e.what();
    warnEvenWhenQuiet(fmt::format("VIS: SuperPoint cannot start ({}): the VIS uses Shi-Tomasi instead (visual.detector."
                                  "superpoint.weights, or visual.detector.type)", what.substr(0, what.find(". "))));
    visual::DetectorConfig fallback = visual.detector;
    fallback.type = visual::DetectorType::kShiTomasi;
    setup.detector = visual::makeDetector(fallback);
    setup.detector_name = "shi-tomasi (SuperPoint unavailable)";
  }
  return setup;
}

RunVis::RunVis(const std::string& config_path, const Calibration& calibration, const imu::PreintegrationConfig& imu,
               const MethodChoice& method)
    : RunVis(loadVisSetup(config_path, method), calibration, imu) {}

RunVis::RunVis(const VisSetup& setup, const Calibration& calibration, const imu::PreintegrationConfig& imu)
    : own_(std::make_unique<vio::VisualOdometry>(setup.config, calibration, imu, setup.detector)),
      vo_(own_.get()),
      detector_name_(setup.detector_name),
      vio_config_(setup.config.vio),
      tracker_(setup.config.tracker) {}

RunVis::RunVis(const VisSetup& setup)
    : detector_name_(setup.detector_name),
      vio_config_(setup.config.vio),
      tracker_(setup.config.tracker) {}

void RunVis::attach(const vio::VisualOdometry* vo, std::size_t frames_in, std::size_t frames_bad) {
  vo_ = vo;
  frames_in_ = frames_in;
  frames_bad_ = frames_bad;
}

RunVis::~RunVis() = default;

void RunVis::onImu(const ImuSample& sample) { own_->addImu(sample); }

void RunVis::onSweep(Time t, const Eigen::Isometry3d& T_world_lidar, const std::vector<Eigen::Vector3f>& points) {
  own_->addSweep(t, T_world_lidar, points);
}

void RunVis::onLisState(const pipeline::ScanOutcome& outcome) {
  if (outcome.loop_closed) own_->onWorldCorrected(outcome.T_new_old);
  if (outcome.has_imu_state) lis_state_ = outcome;
  if (!outcome.vis_reset.empty() && own_->estimator().initialized()) {
    own_->reset();
    noteReset(outcome.t, "reset by the LIS: " + outcome.vis_reset);
  }
}

void RunVis::noteReset(Time t, const std::string& why) {
  ++resets_;
  if (resets_ <= kShownResets) spdlog::warn("VIS reset at {:.3f} s: {}", toSeconds(t), why);
  if (resets_ == kShownResets) spdlog::warn("VIS: further resets are counted in report.json, not shown");
  if (events_.size() < kMaxEvents) events_.push_back({t, "reset", why});
  waiting_since_ = t;
  waiting_reported_ = false;
}

// A VIS that stays out after a reset says why, once a wait is long enough to matter (the LIS runs without its help
// meanwhile), and again with the last reason when it comes back: the first initialisation has its own line.
void RunVis::noteWaiting(const vio::FrameResult& r) {
  constexpr Time kReportAfter = 2'000'000'000;  // [ns]
  if (!waiting_since_) return;
  const Time waited = r.t - *waiting_since_;
  if (r.just_initialized) {
    if (waited >= kReportAfter && events_.size() < kMaxEvents)
      events_.push_back({r.t, "waited", fmt::format("{:.1f} s since the reset; the last reason: {}",
                                                    toSeconds(waited), waiting_.empty() ? "none given" : waiting_)});
    waiting_since_.reset();
    return;
  }
  if (waiting_reported_ || waited < kReportAfter || r.event.empty()) return;
  waiting_reported_ = true;
  spdlog::info("VIS {:.1f} s after its reset, {}", toSeconds(waited), r.event);
  if (events_.size() < kMaxEvents) events_.push_back({r.t, "waiting", r.event});
}

// The LIS's state at a camera stamp: the IMU-rate pose, a velocity from the poses 40 ms apart (first order; the
// window's IMU factors refine it), and the biases of its newest fused sweep.
std::optional<vio::SeedState> RunVis::seedAt(Time t, const pipeline::LidarOdometry& lis) const {
  if (!lis_state_ || !lis.stats().imu_initialized || lis.stats().scans_processed < pipeline::kLisSeedMinSweeps)
    return std::nullopt;
  return pipeline::lisSeedAt(lis.recentImuRate(), t, imu::ImuBias{lis_state_->gyro_bias, lis_state_->acc_bias});
}

void RunVis::onFrame(const CameraFrame& frame, const pipeline::LidarOdometry* lis, TrackAhead* ahead) {
  ++frames_in_;
  vio::VisualOdometry::PoseAt pose_at;
  vio::Seeder seed;
  if (lis != nullptr) {
    pose_at = [lis](Time t) { return pipeline::lisPoseAt(lis->recentImuRate(), t); };
    // The VIS waits for the LIS to seed it while the LIS can: it fuses the IMU, or is still starting (its first
    // sweeps). An LIS that gave the IMU up (lidar only) cannot seed: the VIS then aligns visually.
    const pipeline::OdometryStats& s = lis->stats();
    const bool lis_can_seed =
        lis->config().use_imu && (s.imu_initialized || s.scans_processed < pipeline::kLisStartSweeps);
    if (lis_can_seed) seed = [this, lis](Time t) { return seedAt(t, *lis); };
  }
  vio::VisFrame f;
  try {
    f = ahead != nullptr ? own_->addTracked(frame.t, ahead->take(frame), pose_at, seed)
                         : own_->addFrame(frame, pose_at, seed);
  } catch (const std::invalid_argument& e) {  // wrong size or type, a stamp not after the previous frame's
    if (++frames_bad_ <= 5) spdlog::warn("camera frame {} skipped: {}", frame.source, e.what());
    if (frames_bad_ == 5) spdlog::warn("camera: further skipped frames are counted, not shown");
    return;
  }
  record(f);
}

void RunVis::record(const vio::VisFrame& f) {
  const vio::FrameResult& r = f.estimate;
  if (r.reset) {
    noteReset(r.t, r.event);
  } else if (r.rescaled) {
    ++rescales_;
    spdlog::info("VIS rescaled at {:.3f} s: {}", toSeconds(r.t), r.event);
    if (events_.size() < kMaxEvents) events_.push_back({r.t, "rescaled", r.event});
  } else if (r.just_initialized) {
    noteWaiting(r);
    if (!first_init_) first_init_ = r.t;
    spdlog::info("VIS {} at {:.3f} s", r.event, toSeconds(r.t));
    if (events_.size() < kMaxEvents) events_.push_back({r.t, "initialized", r.event});
  } else if (!r.initialized && !r.event.empty()) {
    waiting_ = r.event;
    noteWaiting(r);
  }
  if (r.coasting && !coasting_) {  // one event per stretch; the frames are counted
    spdlog::info("VIS at {:.3f} s: {}", toSeconds(r.t), r.event);
    if (events_.size() < kMaxEvents) events_.push_back({r.t, "coasting", r.event});
  }
  coasting_ = r.coasting;
  coasted_ += r.coasting ? 1 : 0;
  new_state_ = states_.onFrame(r);
  if (r.initialized) {
    ++estimated_;
    if (!trajectory_ && !trajectory_path_.empty())
      trajectory_ = std::make_unique<ImuRateFile>(trajectory_path_, T_imu_body_);
    if (trajectory_) trajectory_->add(r.t, r.T_world_imu);
  }
  sums_.add(f);
  if (!frames_.streaming() && !frames_path_.empty()) frames_.streamTo(frames_path_);
  frames_.add(frameLine(f));
}

void RunVis::streamTo(const std::string& frames_path, const std::string& trajectory_path,
                      const Eigen::Isometry3d& T_imu_body) {
  frames_path_ = frames_path;
  trajectory_path_ = trajectory_path;
  T_imu_body_ = T_imu_body;
}

ImuRateFile::Summary RunVis::finishFiles() {
  if (frames_.streaming()) frames_.finish(frames_path_);
  ImuRateFile::Summary s;
  if (trajectory_) s = trajectory_->copyTo(trajectory_path_);  // flushes
  trajectory_.reset();
  frames_path_.clear(), trajectory_path_.clear();  // a frame after this is counted, not written
  return s;
}

void VisFrameSums::add(const vio::VisFrame& f) {
  const vio::FrameResult& r = f.estimate;
  ++frames;
  keyframes += r.keyframe ? 1 : 0;
  keyframes_by_time += r.keyframe_by_time ? 1 : 0;
  detected += f.detected ? 1 : 0;
  topped_up += f.front_added_corners > 0 ? 1 : 0;
  corners += static_cast<std::size_t>(f.front_added_corners);
  tracked += f.front_tracked, with_depth += r.with_lidar_depth, share_three += f.share_three;
  on_ground += r.on_ground;
  ms.track += f.ms.track, ms.depth += f.ms.depth, ms.solve += f.ms.solve, ms.marginalize += f.ms.marginalize;
  ms.covariance += f.ms.covariance, ms.total += f.ms.total;
}

std::optional<pipeline::VisualState> RunVis::takeState() {
  std::optional<pipeline::VisualState> s = std::move(new_state_);
  new_state_.reset();
  return s;
}

Json RunVis::report() const {
  Json j;
  j["detector"] = detector_name_;
  j["lk_min_eigenvalue"] = tracker_.min_eigenvalue;
  // Shi-Tomasi corners where fewer than `below` tracks came through a frame (visual::FeatureTrackerConfig::top_up_below).
  if (tracker_.top_up_below > 0)
    j["corner_top_up"] = {{"below", tracker_.top_up_below},
                          {"lk_min_eigenvalue", tracker_.top_up_min_eigenvalue},
                          {"frames", sums_.topped_up},
                          {"corners", sums_.corners}};
  j["depth_mode"] = vio::toString(vio_config_.depth_mode);
  j["init_mode"] = vio::toString(vio_config_.init);
  j["frames_in"] = frames_in_;
  j["frames_bad"] = frames_bad_;
  j["frames_estimated"] = estimated_;
  j["initialized"] = first_init_.has_value();
  if (first_init_) j["first_init_s"] = toSeconds(*first_init_);
  if (!first_init_) j["not_initialized_because"] = waiting_;
  j["resets"] = resets_;
  j["rescales"] = rescales_;
  j["frames_coasted"] = coasted_;
  j["scale_checks"] = vo_ != nullptr ? vo_->estimator().scaleChecks() : 0;
  j["time_offset_s"] = vo_ != nullptr ? vo_->estimator().timeOffset() : 0.0;
  Json events = Json::array();
  for (const Event& e : events_) events.push_back({{"t", toSeconds(e.t)}, {"kind", e.kind}, {"what", e.what}});
  j["events"] = events;
  // Means over the frames; the frames themselves are in vis_frames.jsonl.
  const VisFrameSums& m = sums_;
  const double d = m.frames > 0 ? static_cast<double>(m.frames) : 1.0;
  j["keyframes"] = m.keyframes;
  j["keyframes_by_time"] = m.keyframes_by_time;  // of them, made by vio.max_keyframe_interval_s alone
  j["frames_detected"] = m.detected;
  j["mean"] = {{"tracked", m.tracked / d},
               {"features_with_lidar_depth", m.with_depth / d},
               {"features_on_ground", m.on_ground / d},
               {"share_features_in_3_or_more_frames", m.share_three / d}};
  j["ms_per_frame"] = {{"track", m.ms.track / d},         {"depth", m.ms.depth / d},
                       {"solve", m.ms.solve / d},         {"marginalize", m.ms.marginalize / d},
                       {"covariance", m.ms.covariance / d}, {"total", m.ms.total / d}};
  return j;
}

}  // namespace drover::cli
