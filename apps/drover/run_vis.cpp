#include "apps/drover/run_vis.hpp"

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

}  // namespace

VisSetup loadVisSetup(const std::string& config_path, const MethodChoice& method) {
  io::VisualConfig visual = config_path.empty() ? io::VisualConfig{} : io::loadVisualConfig(config_path);
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
      vio_config_(setup.config.vio) {}

RunVis::RunVis(const VisSetup& setup) : detector_name_(setup.detector_name), vio_config_(setup.config.vio) {}

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
    if (!first_init_) first_init_ = r.t;
    spdlog::info("VIS {} at {:.3f} s", r.event, toSeconds(r.t));
    if (events_.size() < kMaxEvents) events_.push_back({r.t, "initialized", r.event});
  } else if (!r.initialized && !r.event.empty()) {
    waiting_ = r.event;
  }
  if (r.coasting && !coasting_) {  // one event per stretch; the frames are counted
    spdlog::info("VIS at {:.3f} s: {}", toSeconds(r.t), r.event);
    if (events_.size() < kMaxEvents) events_.push_back({r.t, "coasting", r.event});
  }
  coasting_ = r.coasting;
  coasted_ += r.coasting ? 1 : 0;
  new_state_ = states_.onFrame(r);
  if (r.initialized) trajectory_.push_back({r.t, r.T_world_imu});
  records_.push_back({r.t, r.initialized, r.keyframe, f.detected, f.front_tracked, r.features, r.with_lidar_depth,
                      r.outliers, r.iterations, f.share_three, f.ms});
}

std::optional<pipeline::VisualState> RunVis::takeState() {
  std::optional<pipeline::VisualState> s = std::move(new_state_);
  new_state_.reset();
  return s;
}

Json RunVis::report() const {
  Json j;
  j["detector"] = detector_name_;
  j["depth_mode"] = vio::toString(vio_config_.depth_mode);
  j["init_mode"] = vio::toString(vio_config_.init);
  j["frames_in"] = frames_in_;
  j["frames_bad"] = frames_bad_;
  j["frames_estimated"] = trajectory_.size();
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
  // Means over the frames, and per frame (compact columns).
  double track = 0, depth = 0, solve = 0, marg = 0, cov = 0, total = 0, tracked = 0, with_depth = 0, three = 0;
  std::size_t n = 0, keyframes = 0, detected = 0;
  Json frames = Json::array();
  for (const VisFrameRecord& r : records_) {
    track += r.ms.track, depth += r.ms.depth, solve += r.ms.solve, marg += r.ms.marginalize, total += r.ms.total;
    cov += r.ms.covariance;
    tracked += r.tracked, with_depth += r.with_depth, three += r.share_three;
    keyframes += r.keyframe ? 1 : 0;
    detected += r.detected ? 1 : 0;
    ++n;
    frames.push_back({toSeconds(r.t), r.initialized, r.tracked, r.features, r.with_depth, r.keyframe, r.outliers,
                      r.ms.total});
  }
  const double d = n > 0 ? static_cast<double>(n) : 1.0;
  j["keyframes"] = keyframes;
  j["frames_detected"] = detected;
  j["mean"] = {{"tracked", tracked / d},
               {"features_with_lidar_depth", with_depth / d},
               {"share_features_in_3_or_more_frames", three / d}};
  j["ms_per_frame"] = {{"track", track / d}, {"depth", depth / d}, {"solve", solve / d},
                       {"marginalize", marg / d}, {"covariance", cov / d}, {"total", total / d}};
  j["frame_columns"] = {"t", "initialized", "tracked", "features", "with_lidar_depth", "keyframe", "outliers", "ms"};
  j["frames"] = frames;
  return j;
}

}  // namespace drover::cli
