// Marginalisation of the frame that leaves the window (VINS-Mono Sec. VI-D) and the failure checks (VINS-Mono's
// failureDetection).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "backend/quaternion_manifold.hpp"
#include "backend/schur_marginalizer.hpp"
#include "backend/visual_factors.hpp"
#include "vio/window_frame.hpp"
#include "vio/window_residuals.hpp"

namespace drover::vio {
namespace {

const backend::RightQuaternionManifold& quaternionManifold() {
  static const backend::RightQuaternionManifold manifold;
  return manifold;
}

// A held (depth_mode fixed) lidar depth is conditioned on, not marginalised: a tight inverse-depth factor makes the
// Schur complement keep the information the fixed depth gave (1 mm at 1 m).
constexpr double kHeldDepthSigma = 1e-3;  // [m per m of depth]

}  // namespace

// Declares every frame, extrinsic and time-offset block the window can put into a residual.
void SlidingWindowEstimator::declareWindowBlocks(backend::SchurMarginalizer& m) {
  for (auto& f : frames_) {
    m.addBlock(f->p, 3, nullptr);
    m.addBlock(f->q, 4, &quaternionManifold());
    m.addBlock(f->v, 3, nullptr);
    m.addBlock(f->bias, 6, nullptr);
  }
  m.addBlock(p_ic_, 3, nullptr);
  m.addBlock(q_ic_, 4, &quaternionManifold());
  m.addBlock(td_, 1, nullptr);
}

SlidingWindowEstimator::Residuals SlidingWindowEstimator::declareWindow(backend::SchurMarginalizer& m,
                                                                      bool for_marginalization_of_oldest) {
  declareWindowBlocks(m);
  Residuals r;
  buildResiduals(r, for_marginalization_of_oldest);
  for (double* d : r.inverse_depths) m.addBlock(d, 1, nullptr);
  return r;
}

std::vector<SlidingWindowEstimator::HeldDepth> SlidingWindowEstimator::heldDepths(const Residuals& r) {
  std::vector<HeldDepth> out;
  for (auto& [id, f] : features_.features())
    if (r.fixed_depths.count(&f.inverse_depth))
      out.push_back({std::make_unique<backend::InverseDepthFactor>(f.depth, kHeldDepthSigma * f.depth),
                     &f.inverse_depth});
  return out;
}

void SlidingWindowEstimator::marginalizeOldest() {
  backend::SchurMarginalizer m;
  const Residuals r = declareWindow(m, true);
  const std::vector<HeldDepth> held = heldDepths(r);
  if (prior_) m.addResidual(prior_.get(), nullptr, prior_->blocks());
  for (auto& item : r.items) m.addResidual(item.cost.get(), item.loss, item.blocks);
  for (const HeldDepth& h : held) m.addResidual(h.factor.get(), nullptr, {h.inverse_depth});
  const Frame& oldest = *frames_.front();
  std::set<const double*> drop{oldest.p, oldest.q, oldest.v, oldest.bias};
  for (double* d : r.inverse_depths) drop.insert(d);
  backend::MarginalResult result = m.marginalize(drop);
  init_prior_.active = false;  // buildResiduals put it in r: it now lives on in the marginal prior
  if (result.ok) prior_ = std::make_unique<backend::MarginalPriorFactor>(std::move(result));
  else prior_.reset();  // the window then floats on its IMU and features until the next marginalisation
}

// The second-newest frame's visual measurements are dropped; only the prior, when it holds that frame, is
// marginalised (VINS-Mono MARGIN_SECOND_NEW). Its IMU interval is merged into the newest by the caller.
void SlidingWindowEstimator::marginalizeSecondNewest() {
  if (!prior_) return;
  const Frame& f = *frames_[frames_.size() - 2];
  const std::vector<double*>& kept = prior_->blocks();
  std::set<const double*> drop;
  for (const double* b : {f.p, f.q, f.v, f.bias})
    if (std::find(kept.begin(), kept.end(), b) != kept.end()) drop.insert(b);
  if (drop.empty()) return;
  backend::SchurMarginalizer m;
  declareWindowBlocks(m);
  m.addResidual(prior_.get(), nullptr, kept);
  backend::MarginalResult result = m.marginalize(drop);
  if (result.ok) prior_ = std::make_unique<backend::MarginalPriorFactor>(std::move(result));
  else prior_.reset();
}

// VINS-Mono does not clear its window for a few tracked features (the check is commented out); LVI-SAM clears it and
// starts again from the LIS. Drover does the latter when a LIS seeds the VIS. Alone, a cleared window must wait for a
// new visual-inertial alignment, which needs acceleration a robot crossing a dark shed at constant speed never gives
// it; and a window started afresh forgets what its marginal prior knew of the biases and the tilt, which at constant
// speed is all that holds the scale. So alone it coasts: the IMU and whatever tracks remain carry the window.
void SlidingWindowEstimator::checkCoasting(FrameResult& result, bool has_seed) {
  const bool few = !result.just_initialized && result.tracked < config_.min_tracked;
  if (!few) {
    coasting_since_.reset();
    return;
  }
  if (has_seed || !(config_.coast_max_s > 0)) return;
  if (!coasting_since_) coasting_since_ = last_output_ ? last_output_->t : result.t;
  if (toSeconds(result.t - *coasting_since_) > config_.coast_max_s) return;  // failure() clears the window
  result.coasting = true;
  result.event = fmt::format("coasting on the IMU: only {} features tracked into the frame (< {}) for {:.2f} s",
                             result.tracked, config_.min_tracked, toSeconds(result.t - *coasting_since_));
}

// VINS-Mono failureDetection, plus a solver failure and an implausible time offset. Empty when healthy.
std::string SlidingWindowEstimator::failure(const FrameResult& result) const {
  const Frame& f = *frames_.back();
  if (solver_failed_) return "the solver failed";
  if (!scale_failure_.empty()) return "the window's " + scale_failure_;
  if (!result.just_initialized && result.tracked < config_.min_tracked && !result.coasting) {
    if (coasting_since_)
      return fmt::format("only {} features tracked into the frame (< {}) for {:.1f} s", result.tracked,
                         config_.min_tracked, toSeconds(result.t - *coasting_since_));
    return fmt::format("only {} features tracked into the frame (< {})", result.tracked, config_.min_tracked);
  }
  const imu::ImuBias b = f.imuBias();
  if (!b.acc.allFinite() || !f.pose().matrix().allFinite() || !f.velocity().allFinite()) return "non-finite state";
  if (b.acc.norm() > config_.max_acc_bias)
    return fmt::format("accelerometer bias {:.2f} m/s^2 > {:.2f}", b.acc.norm(), config_.max_acc_bias);
  if (b.gyro.norm() > config_.max_gyro_bias)
    return fmt::format("gyro bias {:.2f} rad/s > {:.2f}", b.gyro.norm(), config_.max_gyro_bias);
  if (f.velocity().norm() > config_.max_speed)
    return fmt::format("speed {:.1f} m/s > {:.1f}", f.velocity().norm(), config_.max_speed);
  if (std::abs(td_[0]) > config_.max_time_offset_s)
    return fmt::format("time offset {:.1f} ms beyond {:.1f} ms", td_[0] * 1e3, config_.max_time_offset_s * 1e3);
  if (!last_output_) return {};
  const Eigen::Isometry3d T = f.pose();
  const Eigen::Isometry3d& L = last_output_->T_world_imu;
  const double jump = (T.translation() - L.translation()).norm();
  if (jump > config_.max_jump_m) return fmt::format("position jumped {:.2f} m between frames", jump);
  const double dz = std::abs(T.translation().z() - L.translation().z());
  if (dz > config_.max_height_jump_m) return fmt::format("height jumped {:.2f} m between frames", dz);
  const double turn = Eigen::AngleAxisd(L.linear().transpose() * T.linear()).angle() * 180.0 / M_PI;
  if (turn > config_.max_turn_deg) return fmt::format("heading jumped {:.1f} deg between frames", turn);
  return {};
}

}  // namespace drover::vio
