// The window's nonlinear least squares (VINS-Mono Sec. VI, Eq. 22): marginal prior, IMU preintegration and bias
// random walk, robust reprojection of every usable feature, and LVI-SAM's lidar depth; then outliers and gauge.
#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include "backend/ground_factor.hpp"
#include "backend/imu_factors.hpp"
#include "backend/quaternion_manifold.hpp"
#include "backend/schur_marginalizer.hpp"
#include "backend/state_prior_factor.hpp"
#include "backend/visual_factors.hpp"
#include "vio/solver_log.hpp"
#include "vio/window_frame.hpp"
#include "vio/window_residuals.hpp"

namespace drover::vio {
namespace {

// VINS-Mono repropagates a preintegration when the bias moved this far from its linearisation point.
constexpr double kRepropagateAcc = 0.10;   // [m/s^2]
constexpr double kRepropagateGyro = 0.01;  // [rad/s]
constexpr double kMinDepth = 0.05;         // [m] in the observing camera for a reprojection factor to be added

double yawOf(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

const backend::RightQuaternionManifold& quaternionManifold() {
  static const backend::RightQuaternionManifold manifold;
  return manifold;
}

// A Gaussian prior on the time offset td [s] around zero (the calibration's value): td is nearly unobservable
// while the window barely moves (a time shift then looks like a position shift of v td), and without a prior the
// first solves after initialisation can throw it tens of milliseconds off.
class TimeOffsetPrior final : public ceres::SizedCostFunction<1, 1> {
 public:
  explicit TimeOffsetPrior(double sigma_s) : weight_(1.0 / sigma_s) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = weight_ * parameters[0][0];
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = weight_;
    return true;
  }

 private:
  double weight_;
};

}  // namespace

void SlidingWindowEstimator::buildResiduals(Residuals& r, bool oldest_only) const {
  r.robust = std::make_unique<ceres::CauchyLoss>(config_.robust_px / config_.sigma_px);
  const std::size_t n = frames_.size();
  if (init_prior_.active) {
    backend::StatePoint at;
    at.p_world = Eigen::Vector3d(init_prior_.p[0], init_prior_.p[1], init_prior_.p[2]);
    at.q_world_imu = Eigen::Quaterniond(init_prior_.q[3], init_prior_.q[0], init_prior_.q[1], init_prior_.q[2]);
    at.v_world = Eigen::Vector3d(init_prior_.v[0], init_prior_.v[1], init_prior_.v[2]);
    at.bias = Eigen::Map<const backend::Vector6d>(init_prior_.bias);
    const backend::Matrix15d L = init_prior_.sigma.cwiseInverse().asDiagonal();
    Frame& f = *frames_.front();
    r.items.push_back({std::make_unique<backend::NavStatePriorFactor>(at, L), nullptr, {f.p, f.q, f.v, f.bias}});
  }
  for (std::size_t k = 1; k < n; ++k) {
    if (oldest_only && k > 1) break;
    Frame& a = *frames_[k - 1];
    Frame& b = *frames_[k];
    if (!b.pre || b.pre->deltaTime() <= 0) continue;
    r.items.push_back({std::make_unique<backend::ImuPreintegrationFactor>(*b.pre), nullptr,
                       {a.p, a.q, a.v, a.bias, b.p, b.q, b.v}});
    r.items.push_back({std::make_unique<backend::BiasRandomWalkFactor>(imu_config_.gyro_bias_random_walk,
                                                                       imu_config_.acc_bias_random_walk,
                                                                       b.pre->deltaTime()),
                       nullptr, {a.bias, b.bias}});
  }
  if (!oldest_only && lis_bias_) {  // the newest frame is never marginalised: the prior never enters the marginal
    backend::Vector6d b;
    b << lis_bias_->gyro, lis_bias_->acc;
    r.items.push_back({std::make_unique<backend::BiasPriorFactor>(b, config_.lis_bias_prior_sigma_gyro,
                                                                  config_.lis_bias_prior_sigma_acc),
                       nullptr, {frames_.back()->bias}});
  }
  // The datasheet's turn-on bias; the gyro's is observable: left free.
  if (!oldest_only && alone_ && config_.acc_bias_prior_sigma > 0) {
    constexpr double kFreeGyroSigma = 1.0;   // [rad/s]
    r.items.push_back({std::make_unique<backend::BiasPriorFactor>(backend::Vector6d::Zero(), kFreeGyroSigma,
                                                                  config_.acc_bias_prior_sigma),
                       nullptr, {frames_.back()->bias}});
  }
  // The longest tracks first (they constrain the window most), up to max_features.
  std::vector<Feature*> used;
  const int newest = static_cast<int>(n) - 1;
  for (auto& [id, f] : const_cast<FeatureManager&>(features_).features())
    if (features_.usable(f, newest, config_.min_observations) && f.depth > 0 && (!oldest_only || f.start() == 0))
      used.push_back(&f);
  std::stable_sort(used.begin(), used.end(),
                   [](const Feature* a, const Feature* b) { return a->obs.size() > b->obs.size(); });
  if (static_cast<int>(used.size()) > config_.max_features)
    used.resize(static_cast<std::size_t>(config_.max_features));
  if (!oldest_only && config_.estimate_time_offset)
    r.items.push_back(
        {std::make_unique<TimeOffsetPrior>(config_.time_offset_sigma_s), nullptr, {const_cast<double*>(td_)}});
  const double sqrt_info = focal_px_ / config_.sigma_px;
  const Eigen::Isometry3d T_ic = T_imu_cam();
  double* p_ic = const_cast<double*>(p_ic_);
  double* q_ic = const_cast<double*>(q_ic_);
  double* td = const_cast<double*>(td_);
  for (Feature* f : used) {
    f->inverse_depth = 1.0 / f->depth;
    r.inverse_depths.push_back(&f->inverse_depth);
    ++r.features;
    r.seen_three_times += f->obs.size() >= 3 ? 1 : 0;
    const Observation& oi = f->obs.front();
    Frame& fi = *frames_[static_cast<std::size_t>(oi.frame)];
    for (std::size_t k = 1; k < f->obs.size(); ++k) {
      const Observation& oj = f->obs[k];
      Frame& fj = *frames_[static_cast<std::size_t>(oj.frame)];
      auto cost = std::make_unique<backend::ReprojectionFactor>(oi.normalized, oj.normalized, oi.velocity,
                                                                oj.velocity, oi.td, oj.td, sqrt_info);
      std::vector<double*> blocks{fi.p, fi.q, fj.p, fj.q, p_ic, q_ic, &f->inverse_depth, td};
      // A point behind the observing camera at the start would fail the whole solve: that observation waits.
      if (!(cost->cheirality(blocks.data()) > kMinDepth)) continue;
      r.items.push_back({std::move(cost), r.robust.get(), std::move(blocks)});
    }
    if (!f->lidar_anchor) {
      if (alone_ && config_.ground_height_m > 0) addGroundFactor(r, *f, T_ic);
      continue;
    }
    ++r.with_lidar_depth;
    if (config_.depth_mode == DepthMode::kFixed) {
      r.fixed_depths.insert(&f->inverse_depth);
    } else if (config_.depth_mode == DepthMode::kFactor) {
      // The measurement is the lidar's depth at the anchor, not f->depth: that is the last solve's estimate, and a
      // factor towards it would only resist change from frame to frame, letting the depth (and the window's scale)
      // walk away from the lidar over the feature's life.
      const double sigma = config_.depth_sigma_m + config_.depth_sigma_rel * oi.lidar_depth +
                           config_.depth_sigma_spread * oi.depth_spread;
      r.items.push_back({std::make_unique<backend::InverseDepthFactor>(oi.lidar_depth, sigma), nullptr,
                         {&f->inverse_depth}});
    }
  }
}

// A feature whose point, as last solved, lies on the surface below its anchor frame's body is held there
// (vio_config.hpp ground_*): the point in the anchor IMU frame is R_ic n depth + p_ic. The gate is relative to the
// camera's height above the surface, h + p_ic.z: a window whose scale is off by a fraction s puts the ground's
// points s times that height off it.
void SlidingWindowEstimator::addGroundFactor(Residuals& r, Feature& f, const Eigen::Isometry3d& T_ic) const {
  const double h = config_.ground_height_m;
  if (!(f.depth > 0)) return;
  const Observation& oi = f.obs.front();
  const Eigen::Vector3d P_b = T_ic * (f.depth * oi.normalized.homogeneous());
  const double range = P_b.head<2>().norm();
  const double gate = config_.ground_gate_rel * std::max(h + T_ic.translation().z(), 0.0);
  if (std::abs(P_b.z() + h) > gate || range > config_.ground_max_range_m) return;
  const double sigma = std::hypot(config_.ground_sigma_m, config_.ground_slope_sigma_rad * range);
  if (!r.ground_robust) r.ground_robust = std::make_unique<ceres::CauchyLoss>(1.0);
  r.items.push_back({std::make_unique<backend::GroundHeightFactor>(oi.normalized, h, sigma), r.ground_robust.get(),
                     {const_cast<double*>(p_ic_), const_cast<double*>(q_ic_), &f.inverse_depth}});
  ++r.on_ground;
}

void SlidingWindowEstimator::optimize(FrameResult& result) {
  quietSolverWarnings();
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t k = 1; k < frames_.size(); ++k) {  // relinearise preintegrations whose bias moved far
    const imu::ImuBias now = frames_[k - 1]->imuBias();
    const imu::ImuBias& hat = frames_[k]->pre->biasHat();
    if ((now.acc - hat.acc).norm() > kRepropagateAcc || (now.gyro - hat.gyro).norm() > kRepropagateGyro)
      integrate(*frames_[k], *frames_[k - 1]);
  }
  features_.initializeDepths(cameraPoses(), config_.depth_mode != DepthMode::kOff);
  const Eigen::Isometry3d T0_before = frames_.front()->pose();

  Residuals r;
  buildResiduals(r, false);
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  auto* manifold = const_cast<backend::RightQuaternionManifold*>(&quaternionManifold());
  for (auto& f : frames_) {
    problem.AddParameterBlock(f->p, 3);
    problem.AddParameterBlock(f->q, 4, manifold);
    problem.AddParameterBlock(f->v, 3);
    problem.AddParameterBlock(f->bias, 6);
  }
  problem.AddParameterBlock(p_ic_, 3);
  problem.AddParameterBlock(q_ic_, 4, manifold);
  problem.AddParameterBlock(td_, 1);
  if (!config_.estimate_extrinsic) {
    problem.SetParameterBlockConstant(p_ic_);
    problem.SetParameterBlockConstant(q_ic_);
  }
  if (!config_.estimate_time_offset) problem.SetParameterBlockConstant(td_);
  if (prior_) problem.AddResidualBlock(prior_.get(), nullptr, prior_->blocks());
  for (auto& item : r.items)
    problem.AddResidualBlock(item.cost.get(), const_cast<ceres::LossFunction*>(item.loss), item.blocks);
  for (double* d : r.inverse_depths)
    if (r.fixed_depths.count(d) && problem.HasParameterBlock(d)) problem.SetParameterBlockConstant(d);
  if (!prior_ && !init_prior_.active) {  // no prior holds the gauge: hold the oldest pose
    problem.SetParameterBlockConstant(frames_.front()->p);
    problem.SetParameterBlockConstant(frames_.front()->q);
  }

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_SCHUR;
  options.trust_region_strategy_type = ceres::DOGLEG;
  options.max_num_iterations = config_.max_iterations;
  options.num_threads = 1;
  if (config_.max_solver_ms > 0 && !deterministic_) options.max_solver_time_in_seconds = config_.max_solver_ms * 1e-3;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size());
  solver_failed_ = summary.termination_type == ceres::FAILURE || !std::isfinite(summary.final_cost);
  result.features = r.features;
  result.with_lidar_depth = r.with_lidar_depth;
  result.on_ground = r.on_ground;

  const std::set<const double*> solved(r.inverse_depths.begin(), r.inverse_depths.end());
  for (auto& [id, f] : features_.features())
    if (solved.count(&f.inverse_depth)) f.depth = f.inverse_depth > 0 ? 1.0 / f.inverse_depth : -1.0;
  fixGauge(T0_before);
  features_.removeFailures();
  share_three_ = r.features > 0 ? static_cast<double>(r.seen_three_times) / r.features : 0;
  result.ms_solve = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// VINS-Mono double2vector: the window is rotated about z and shifted so that the oldest frame keeps the yaw and
// position it had before the solve (the 4 unobservable directions of visual-inertial odometry).
void SlidingWindowEstimator::fixGauge(const Eigen::Isometry3d& T0_before) {
  const Eigen::Isometry3d T0_after = frames_.front()->pose();
  const double dyaw = yawOf(T0_before.linear()) - yawOf(T0_after.linear());
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(dyaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (auto& f : frames_) {
    Eigen::Isometry3d T = f->pose();
    T.linear() = Rz * T.linear();
    T.translation() = Rz * (T.translation() - T0_after.translation()) + T0_before.translation();
    f->setPose(T);
    f->setVelocity(Rz * f->velocity());
  }
}

void SlidingWindowEstimator::removeOutliers(FrameResult& result) {
  const std::vector<Eigen::Isometry3d> T_wc = cameraPoses();
  const int newest = static_cast<int>(frames_.size()) - 1;
  std::vector<std::pair<std::uint64_t, int>> drop;
  for (const auto& [id, f] : features_.features()) {
    if (!features_.usable(f, newest, config_.min_observations) || f.depth <= 0) continue;
    const Observation& a = f.obs.front();
    const Eigen::Vector2d na = a.normalized - (td_[0] - a.td) * a.velocity;
    const Eigen::Vector3d p_w = T_wc[static_cast<std::size_t>(a.frame)] * (f.depth * na.homogeneous());
    for (std::size_t k = 1; k < f.obs.size(); ++k) {
      const Observation& o = f.obs[k];
      const Eigen::Vector3d p_c = T_wc[static_cast<std::size_t>(o.frame)].inverse() * p_w;
      const Eigen::Vector2d n = o.normalized - (td_[0] - o.td) * o.velocity;
      const double err_px = p_c.z() > 0 ? focal_px_ * (p_c.hnormalized() - n).norm() : 1e9;
      if (err_px > config_.outlier_px) drop.emplace_back(id, o.frame);
    }
  }
  for (const auto& [id, frame] : drop) features_.removeObservation(id, frame);
  result.outliers = static_cast<int>(drop.size());
}

}  // namespace drover::vio
