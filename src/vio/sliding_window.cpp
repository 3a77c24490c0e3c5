// Frame bookkeeping of the sliding window: IMU intervals, prediction, the keyframe decision, initialisation and
// sliding. The solve and the marginalisation are in window_optimize.cpp and window_marginalize.cpp.
#include "vio/sliding_window.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "backend/schur_marginalizer.hpp"
#include "vio/seed_agreement.hpp"
#include "vio/window_frame.hpp"

namespace drover::vio {

SlidingWindowEstimator::SlidingWindowEstimator(const VioConfig& config, const imu::PreintegrationConfig& imu_config,
                                               const Eigen::Isometry3d& T_imu_cam, double focal_px)
    : config_(config), imu_config_(imu_config), focal_px_(focal_px) {
  if (const std::string bad = config.validate(); !bad.empty()) throw std::invalid_argument("vio: " + bad);
  if (const std::string bad = imu_config.validate(); !bad.empty()) throw std::invalid_argument("vio imu: " + bad);
  if (!(focal_px > 0) || !std::isfinite(focal_px)) throw std::invalid_argument("vio: focal length must be > 0");
  const Eigen::Quaterniond q(T_imu_cam.rotation());
  q_ic_[0] = q.x(), q_ic_[1] = q.y(), q_ic_[2] = q.z(), q_ic_[3] = q.w();
  Eigen::Map<Eigen::Vector3d>{p_ic_} = T_imu_cam.translation();
}

SlidingWindowEstimator::~SlidingWindowEstimator() = default;

Eigen::Isometry3d SlidingWindowEstimator::T_imu_cam() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(q_ic_[3], q_ic_[0], q_ic_[1], q_ic_[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p_ic_[0], p_ic_[1], p_ic_[2]);
  return T;
}

Time SlidingWindowEstimator::imuTime(Time t_camera) const {
  return t_camera + static_cast<Time>(std::llround(td_[0] * 1e9));
}

// The preintegration holds each sample until the next one (zero-order hold). With config.imu_midpoint the held
// value is the mean of the sample and the next one, which makes the integration VINS-Mono's mid-point rule (second
// order): at 200 Hz and 1.5 rad/s^2 the hold alone lags the attitude by half a sample, which the window would
// otherwise absorb as ~4e-3 rad/s of gyro bias.
void SlidingWindowEstimator::addImu(const ImuSample& sample) {
  if (!imu_.empty() && sample.t <= imu_.back().t) return;  // the caller checks order; never integrate backwards
  if (config_.imu_midpoint && !imu_.empty()) {
    ImuSample& previous = imu_.back();
    previous.omega_imu = 0.5 * (raw_newest_omega_ + sample.omega_imu);
    previous.acc_imu = 0.5 * (raw_newest_acc_ + sample.acc_imu);
  }
  raw_newest_omega_ = sample.omega_imu;
  raw_newest_acc_ = sample.acc_imu;
  imu_.push_back(sample);
}

// The samples that cover [t0, t1] (the last one at or before t0 first) and the buffer pruned to the last sample at
// or before t1, which starts the next interval.
std::vector<ImuSample> SlidingWindowEstimator::takeImu(Time t0, Time t1) {
  std::vector<ImuSample> out;
  auto first = std::upper_bound(imu_.begin(), imu_.end(), t0, [](Time t, const ImuSample& s) { return t < s.t; });
  if (first == imu_.begin()) return out;  // nothing at or before t0: the interval is not covered
  --first;
  auto last = std::upper_bound(imu_.begin(), imu_.end(), t1, [](Time t, const ImuSample& s) { return t < s.t; });
  out.assign(first, last);
  if (last != imu_.begin()) imu_.erase(imu_.begin(), std::prev(last));
  return out;
}

namespace {
// [s] the longest stretch of [t0, t1] without an IMU sample (infinite when none is at or before t0).
double largestGap(const std::vector<ImuSample>& samples, Time t0, Time t1) {
  if (samples.empty() || samples.front().t > t0) return std::numeric_limits<double>::infinity();
  double gap = toSeconds(t1 - samples.back().t);
  for (std::size_t k = 1; k < samples.size(); ++k) gap = std::max(gap, toSeconds(samples[k].t - samples[k - 1].t));
  return gap;
}
}  // namespace

void SlidingWindowEstimator::integrate(Frame& frame, const Frame& previous) const {
  frame.pre.emplace(previous.imuBias(), imu_config_);
  frame.pre->integrateRange(frame.imu, previous.t, frame.t);
}

// Forster et al. Eq. 38: the new frame's state from the previous one and the preintegration.
void SlidingWindowEstimator::predict(Frame& frame, const Frame& previous) const {
  const imu::Preintegrator& pre = *frame.pre;
  const double dt = pre.deltaTime();
  const Eigen::Vector3d g(0, 0, -imu_config_.gravity);
  const Eigen::Isometry3d Ti = previous.pose();
  const Eigen::Matrix3d& Ri = Ti.linear();
  Eigen::Isometry3d Tj = Eigen::Isometry3d::Identity();
  Tj.linear() = Ri * pre.deltaR();
  Tj.translation() = Ti.translation() + previous.velocity() * dt + 0.5 * g * dt * dt + Ri * pre.deltaP();
  frame.setPose(Tj);
  frame.setVelocity(previous.velocity() + g * dt + Ri * pre.deltaV());
  frame.setBias(previous.imuBias());
}

std::vector<Eigen::Isometry3d> SlidingWindowEstimator::cameraPoses() const {
  std::vector<Eigen::Isometry3d> out;
  const Eigen::Isometry3d T_ic = T_imu_cam();
  for (const auto& f : frames_) out.push_back(f->pose() * T_ic);
  return out;
}

void SlidingWindowEstimator::reset() {
  init_prior_.active = false;
  lis_bias_.reset();
  coasting_since_.reset();
  aligned_visually_ = false;
  history_.clear();
  history_next_imu_.clear();
  scale_failure_.clear();
  pending_ground_scale_.reset();
  frames_.clear();
  features_.clear();
  prior_.reset();
  initialized_ = false;
  last_output_.reset();
}

FrameResult SlidingWindowEstimator::addFrame(Time t_camera, const std::vector<FrameFeature>& features,
                                             const Seeder& seed) {
  FrameResult result;
  result.t = imuTime(t_camera);
  if (!frames_.empty() && result.t <= frames_.back()->t) {
    result.event = "frame stamp not after the previous frame's: skipped";
    if (last_output_) result.initialized = initialized_;
    return result;
  }
  auto frame = std::make_unique<Frame>();
  frame->t = result.t;
  frame->imu = takeImu(frames_.empty() ? result.t : frames_.back()->t, result.t);
  if (!frames_.empty()) {
    const double gap = largestGap(frame->imu, frames_.back()->t, result.t);
    if (gap > config_.max_imu_gap_s) {
      const bool was = initialized_;
      reset();
      result.reset = was;
      result.event = std::isinf(gap) ? "no IMU data covers the interval since the previous frame: window cleared"
                                     : fmt::format("no IMU data for {:.3f} s before the frame: window cleared", gap);
    }
  }
  for (const FrameFeature& f : features) frame->seen.emplace(f.id, f.normalized);
  const int index = static_cast<int>(frames_.size());
  const double parallax = features_.addFrame(index, features, td_[0]);
  result.tracked = features_.lastTracked();
  const bool by_parallax = index < 2 || parallax < 0 || result.tracked < config_.min_tracked_for_parallax ||
                           parallax * config_.focal_px >= config_.min_parallax_px;
  const bool keyframe = by_parallax || keyframeIsDue();
  if (!frames_.empty()) {
    integrate(*frame, *frames_.back());
    if (initialized_) predict(*frame, *frames_.back());
  }
  frames_.push_back(std::move(frame));

  if (!initialized_) {
    if (!tryInitialize(seed, result)) {
      if (static_cast<int>(frames_.size()) > config_.window) slide(keyframe || waiting_for_older_, result);
      return result;
    }
  }
  lis_bias_.reset();
  // The LIS's state is looked up only when a prior or the ground needs it, as before the ground existed.
  const bool need_lis =
      config_.lis_bias_prior_sigma_acc > 0 || config_.ground_height_m > 0 || config_.acc_bias_prior_sigma > 0;
  const std::optional<SeedState> lis = seed && need_lis ? seed(frames_.back()->t) : std::nullopt;
  if (lis && config_.lis_bias_prior_sigma_acc > 0) lis_bias_ = lis->bias;
  alone_ = !lis;  // the ground and the turn-on bias prior act only then (vio_config.hpp)
  optimize(result);
  removeOutliers(result);
  checkCoasting(result, static_cast<bool>(seed));
  if (const std::string why = failure(result); !why.empty()) {
    reset();
    result.reset = true;
    result.initialized = false;
    result.event = why + ": window cleared, re-initialising";
    return result;
  }
  checkGroundScale(result);       // may rescale the window to the ground's scale
  checkScaleOverHistory(result);  // may rescale the window: this frame's output is then the first of the new scale
  fillResult(result);
  if (config_.relative_covariance) {
    const auto start = std::chrono::steady_clock::now();
    result.relative_covariance = newestRelativeCovariance();
    result.ms_covariance =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  last_output_ = result;
  if (static_cast<int>(frames_.size()) > config_.window) slide(keyframe, result);
  result.keyframe_by_time = result.keyframe && !by_parallax;
  return result;
}

bool SlidingWindowEstimator::tryInitialize(const Seeder& seed, FrameResult& result) {
  const int have = static_cast<int>(frames_.size());
  if (have <= config_.window) {
    if (result.event.empty())
      result.event = fmt::format("initialising: window {} of {} frames", have, config_.window + 1);
    return false;
  }
  std::string why;
  bool ok = false;
  // LVI-SAM: while the LIS runs, the VIS starts from its state; the window waits until the LIS covers it.
  if (config_.init == InitMode::kLis || (config_.init == InitMode::kAuto && seed)) {
    if (seed && result.tracked < config_.min_tracked) {
      // With a LIS the failure check clears a window whose newest frame tracks fewer than min_tracked features,
      // from the frame after the initialisation on (failure()): initialising on fewer only starts the next reset.
      // On the farm's white walls and a covered camera that was an initialisation and a reset every 0.8 s.
      why = fmt::format("only {} features tracked into the newest frame (< min_tracked {})", result.tracked,
                        config_.min_tracked);
      waiting_for_older_ = false;
      result.event = "not initialised: " + why;
      return false;
    }
    ok = initializeFromSeed(seed, why);
    if (ok) result.event = "initialised from the LIS (" + why + ")";
    // Frames older than the LIS's first state can never be seeded: let the oldest go.
    waiting_for_older_ = !ok && seed && !seed(frames_.front()->t) && seed(frames_.back()->t);
  } else {
    ok = initializeVisually(why);
    if (ok) result.event = "initialised by visual-inertial alignment: " + why;
  }
  if (!ok) {
    result.event = "not initialised: " + why;
    return false;
  }
  initialized_ = true;
  result.just_initialized = true;
  return true;
}

void SlidingWindowEstimator::setInitPrior(double sigma_rotation, double sigma_velocity, double sigma_gyro_bias,
                                          double sigma_acc_bias) {
  init_prior_.active = true;
  const Frame& f = *frames_.front();
  std::copy(f.p, f.p + 3, init_prior_.p);
  std::copy(f.q, f.q + 4, init_prior_.q);
  std::copy(f.v, f.v + 3, init_prior_.v);
  std::copy(f.bias, f.bias + 6, init_prior_.bias);
  init_prior_.sigma << Eigen::Vector3d::Constant(config_.init_sigma_position_m),
      Eigen::Vector3d::Constant(sigma_rotation), Eigen::Vector3d::Constant(sigma_velocity), Eigen::Vector3d::Constant(sigma_gyro_bias),
      Eigen::Vector3d::Constant(sigma_acc_bias);
}

bool SlidingWindowEstimator::initializeFromSeed(const Seeder& seed, std::string& why) {
  if (!seed) {
    why = "no LIS runs (init: lis needs the lidar)";
    return false;
  }
  std::vector<SeedState> states;
  for (const auto& f : frames_) {
    std::optional<SeedState> s = seed(f->t);
    if (!s) {
      why = fmt::format("waiting for the LIS: it has no state at {:.3f} s", toSeconds(f->t));
      return false;
    }
    states.push_back(*s);
  }
  for (std::size_t k = 0; k < frames_.size(); ++k) {
    frames_[k]->setPose(states[k].T_world_imu);
    frames_[k]->setVelocity(states[k].v_world);
    frames_[k]->setBias(states[k].bias);
    if (k > 0) integrate(*frames_[k], *frames_[k - 1]);
  }
  const std::vector<Eigen::Isometry3d> T_wc = cameraPoses();
  features_.initializeDepths(T_wc, config_.depth_mode != DepthMode::kOff);
  const SeedAgreement agreement = seedAgreement(features_, T_wc, config_.focal_px);
  // On success `why` says how the seed agreed (the event's detail, as the visual alignment's).
  why = fmt::format("its motion reprojects the lidar-depth tracks to a median {:.1f} px over {}", agreement.median_px,
                    agreement.observations);
  const bool enough = agreement.observations >= static_cast<std::size_t>(config_.seed_min_observations);
  if (config_.seed_max_median_px > 0 && enough && agreement.median_px > config_.seed_max_median_px) {
    why = fmt::format("the LIS's seed disagrees with the tracks: {} (> {:.1f} px)", why, config_.seed_max_median_px);
    for (auto& [id, f] : features_.features())
      if (!f.lidar_anchor) f.depth = 0;  // triangulated with the refused poses
    return false;
  }
  // The LIS's attitude is gravity-aligned by its own smoother and its biases are fused over many sweeps.
  setInitPrior(config_.lis_sigma_rotation_rad, config_.lis_sigma_velocity, config_.lis_sigma_gyro_bias,
               config_.lis_sigma_acc_bias);
  return true;
}

void SlidingWindowEstimator::fillResult(FrameResult& result) const {
  const Frame& f = *frames_.back();
  result.initialized = true;
  result.T_world_imu = f.pose();
  result.v_world = f.velocity();
  result.bias = f.imuBias();
  result.td = td_[0];
}

bool SlidingWindowEstimator::keyframeIsDue() const {
  const std::size_t n = frames_.size();  // before the newest frame is pushed: [n-1] is then the second-newest
  return initialized_ && config_.max_keyframe_interval_s > 0 && n >= 2 &&
         frames_[n - 1]->t - frames_[n - 2]->t >= fromSeconds(config_.max_keyframe_interval_s);
}

// One frame leaves: the oldest when the second-newest is a keyframe, else the second-newest (VINS slideWindow).
void SlidingWindowEstimator::slide(bool keyframe, FrameResult& result) {
  const auto start = std::chrono::steady_clock::now();
  const bool use_lidar = config_.depth_mode != DepthMode::kOff;
  result.keyframe = keyframe;
  if (keyframe) {
    if (initialized_) {
      recordOldest();
      marginalizeOldest();
    }
    const Eigen::Isometry3d T_ic = T_imu_cam();
    features_.removeOldest(frames_[0]->pose() * T_ic, frames_[1]->pose() * T_ic, use_lidar && initialized_);
    frames_.pop_front();
    frames_.front()->pre.reset();
    frames_.front()->imu.clear();
  } else {
    if (initialized_) marginalizeSecondNewest();
    const int newest = static_cast<int>(frames_.size()) - 1;
    Frame& last = *frames_[static_cast<std::size_t>(newest)];
    Frame& dropped = *frames_[static_cast<std::size_t>(newest - 1)];
    std::vector<ImuSample> merged = dropped.imu;
    for (const ImuSample& s : last.imu)
      if (merged.empty() || s.t > merged.back().t) merged.push_back(s);
    last.imu = std::move(merged);
    frames_.erase(frames_.begin() + newest - 1);
    integrate(last, *frames_[static_cast<std::size_t>(newest - 2)]);
    features_.removeSecondNewest(newest);
  }
  result.ms_marginalize =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace drover::vio
