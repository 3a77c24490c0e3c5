#include "backend/fixed_lag_smoother.hpp"

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "backend/quaternion_manifold.hpp"
#include "backend/smoother_window.hpp"

namespace drover::backend {

namespace {

bool positiveFinite(double x) { return std::isfinite(x) && x > 0; }

// LIO-SAM's failureDetection(): a velocity or bias no robot has means the estimate diverged. Names every
// offending value of the node (empty when plausible).
std::string implausibility(const WindowNode& node, const FixedLagSmootherConfig& config) {
  const imu::NavState s = node.navState();
  const imu::ImuBias b = node.imuBias();
  if (!s.T_world_imu.matrix().allFinite() || !s.v_world.allFinite() || !b.gyro.allFinite() || !b.acc.allFinite()) {
    return "state is not finite";
  }
  std::ostringstream out;
  if (s.v_world.norm() > config.max_velocity) {
    out << "large velocity |v| = " << s.v_world.norm() << " m/s > " << config.max_velocity << "; ";
  }
  if (b.gyro.norm() > config.max_bias) {
    out << "large gyro bias |b_g| = " << b.gyro.norm() << " rad/s > " << config.max_bias << "; ";
  }
  if (b.acc.norm() > config.max_bias) {
    out << "large accelerometer bias |b_a| = " << b.acc.norm() << " m/s^2 > " << config.max_bias << "; ";
  }
  std::string reason = out.str();
  if (!reason.empty()) reason.resize(reason.size() - 2);  // the last "; "
  return reason;
}

}  // namespace

std::string FixedLagSmootherConfig::validate() const {
  std::ostringstream out;
  if (window < 2) out << "window = " << window << " must be >= 2; ";
  if (max_iterations < 1) out << "max_iterations = " << max_iterations << " must be >= 1; ";
  const std::pair<const char*, double> positives[] = {
      {"lidar_sigma_position", lidar_sigma_position},   {"lidar_sigma_rotation", lidar_sigma_rotation},
      {"prior_sigma_position", prior_sigma_position},   {"prior_sigma_rotation", prior_sigma_rotation},
      {"prior_sigma_velocity", prior_sigma_velocity},   {"prior_sigma_gyro_bias", prior_sigma_gyro_bias},
      {"prior_sigma_acc_bias", prior_sigma_acc_bias},   {"min_gyro_bias_random_walk", min_gyro_bias_random_walk},
      {"min_acc_bias_random_walk", min_acc_bias_random_walk}, {"max_velocity", max_velocity},
      {"max_bias", max_bias}};
  for (const auto& [name, value] : positives) {
    if (!positiveFinite(value)) out << name << " = " << value << " must be finite and > 0; ";
  }
  return out.str();
}

struct FixedLagSmoother::Impl {
  Config config;
  bool initialized = false;
  SmootherWindow window;
  RightQuaternionManifold manifold;

  SmootherUpdate solve(SmootherUpdate update);
};

FixedLagSmoother::FixedLagSmoother(const Config& config) : impl_(std::make_unique<Impl>()) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("FixedLagSmootherConfig: " + error);
  impl_->config = config;
}

FixedLagSmoother::~FixedLagSmoother() = default;
FixedLagSmoother::FixedLagSmoother(FixedLagSmoother&&) noexcept = default;
FixedLagSmoother& FixedLagSmoother::operator=(FixedLagSmoother&&) noexcept = default;

void FixedLagSmoother::initialize(const imu::NavState& state, const imu::ImuBias& bias,
                                  const imu::PreintegrationConfig& imu) {
  const std::string error = imu.validate();
  if (!error.empty()) throw std::invalid_argument("FixedLagSmoother::initialize: PreintegrationConfig: " + error);
  if (!state.T_world_imu.matrix().allFinite() || !state.v_world.allFinite() || !bias.gyro.allFinite() ||
      !bias.acc.allFinite()) {
    throw std::invalid_argument("FixedLagSmoother::initialize: state or bias is not finite");
  }
  const Config& c = impl_->config;
  SmootherWindow& w = impl_->window;
  w.nodes.clear();
  w.nodes.emplace_back();
  w.nodes.back().set(state, bias);
  w.gyro_random_walk = std::max(imu.gyro_bias_random_walk, c.min_gyro_bias_random_walk);
  w.acc_random_walk = std::max(imu.acc_bias_random_walk, c.min_acc_bias_random_walk);
  Vector15d inv_sigma;
  inv_sigma << Eigen::Vector3d::Constant(1 / c.prior_sigma_position),
      Eigen::Vector3d::Constant(1 / c.prior_sigma_rotation), Eigen::Vector3d::Constant(1 / c.prior_sigma_velocity),
      Eigen::Vector3d::Constant(1 / c.prior_sigma_gyro_bias), Eigen::Vector3d::Constant(1 / c.prior_sigma_acc_bias);
  w.prior = {w.nodes.back().statePoint(), inv_sigma.asDiagonal(), Vector15d::Zero()};
  impl_->initialized = true;
}

void FixedLagSmoother::setFirstVelocitySigma(double sigma) {
  if (!std::isfinite(sigma) || sigma <= 0)
    throw std::invalid_argument("FixedLagSmoother::setFirstVelocitySigma: sigma must be finite and > 0");
  if (!impl_->initialized || impl_->window.nodes.size() != 1)
    throw std::logic_error("FixedLagSmoother::setFirstVelocitySigma: only on a freshly initialized window");
  // r = L dx with dx = [dp, dtheta, dv, dbg, dba]: the velocity rows are 6..8, and the prior is diagonal there.
  impl_->window.prior.sqrt_information.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() / sigma;
}

namespace {

// U with U^T U = C^-1 for a finite, symmetric, positive definite C; nothing otherwise.
template <int N>
std::optional<Eigen::Matrix<double, N, N>> sqrtInformation(const Eigen::Matrix<double, N, N>& C) {
  using Matrix = Eigen::Matrix<double, N, N>;
  if (!C.allFinite() || (C - C.transpose()).norm() > 1e-9 * C.norm()) return std::nullopt;
  const Eigen::LLT<Matrix> information(Matrix(0.5 * (C + C.transpose())).inverse());
  if (information.info() != Eigen::Success) return std::nullopt;
  const Matrix U = information.matrixU().toDenseMatrix();
  if (!U.allFinite()) return std::nullopt;
  return U;
}

}  // namespace

void FixedLagSmoother::initialize(const imu::NavState& state, const imu::ImuBias& bias,
                                  const imu::PreintegrationConfig& imu, const Eigen::Matrix3d& gyro_bias_covariance) {
  const std::optional<Eigen::Matrix3d> U = sqrtInformation<3>(gyro_bias_covariance);
  if (!U)
    throw std::invalid_argument("FixedLagSmoother::initialize: the gyro bias covariance is not finite, symmetric "
                                "and positive definite");
  initialize(state, bias, imu);
  impl_->window.prior.sqrt_information.block<3, 3>(9, 9) = *U;  // r = L dx: the gyro bias rows are 9..11
}

void FixedLagSmoother::initialize(const imu::NavState& state, const imu::ImuBias& bias,
                                  const imu::PreintegrationConfig& imu,
                                  const Eigen::Matrix<double, 6, 6>& bias_covariance) {
  const std::optional<Eigen::Matrix<double, 6, 6>> U = sqrtInformation<6>(bias_covariance);
  if (!U)
    throw std::invalid_argument("FixedLagSmoother::initialize: the bias covariance is not finite, symmetric and "
                                "positive definite");
  initialize(state, bias, imu);
  impl_->window.prior.sqrt_information.block<6, 6>(9, 9) = *U;  // gyro rows 9..11, accelerometer 12..14
}

// The window's Gauss-Newton information H = J^T J at the current estimate, with J the whitened Jacobian in the
// tangent spaces of the blocks taken in the window's order (p, q, v, b of each node, oldest first), and its
// inverse's block of the newest bias. Not ceres::Covariance: that orders its columns by the blocks' addresses,
// which differ from run to run (each node is its own allocation), so its last bits did too, and through a loop
// correction's restart (ImuFusion::reanchor) every replay with a loop closure differed from its first loop on.
std::optional<Eigen::Matrix<double, 6, 6>> FixedLagSmoother::biasCovariance() const {
  if (!impl_->initialized) return std::nullopt;
  SmootherWindow window = impl_->window;  // the problem points into the nodes: a copy keeps this const
  RightQuaternionManifold manifold;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  window.buildProblem(problem, &manifold);
  ceres::Problem::EvaluateOptions evaluate;
  for (WindowNode& node : window.nodes)
    for (double* block : node.blocks()) evaluate.parameter_blocks.push_back(block);
  ceres::CRSMatrix crs;
  if (!problem.Evaluate(evaluate, nullptr, nullptr, nullptr, &crs)) return std::nullopt;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row)
    for (int k = crs.rows[static_cast<std::size_t>(row)]; k < crs.rows[static_cast<std::size_t>(row) + 1]; ++k)
      J(row, crs.cols[static_cast<std::size_t>(k)]) = crs.values[static_cast<std::size_t>(k)];
  // H^-1 = V S^-2 V^T from J's singular value decomposition (not from H, whose condition is J's squared). Refused,
  // as ceres::Covariance's DENSE_SVD refuses it with its default min_reciprocal_condition_number 1e-14, when
  // (sigma_min / sigma_max)^2 < 1e-14.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeThinV);
  const Eigen::VectorXd sigma = svd.singularValues();  // descending
  if (sigma.size() != J.cols() || !sigma.allFinite() ||
      !(sigma(sigma.size() - 1) * sigma(sigma.size() - 1) > 1e-14 * sigma(0) * sigma(0)))
    return std::nullopt;
  const Eigen::MatrixXd V = svd.matrixV().bottomRows(6);  // the newest node's bias: the last tangent block
  const Eigen::Matrix<double, 6, 6> C = V * sigma.cwiseAbs2().cwiseInverse().asDiagonal() * V.transpose();
  if (!C.allFinite()) return std::nullopt;
  return Eigen::Matrix<double, 6, 6>(0.5 * (C + C.transpose()));
}

std::optional<Eigen::Matrix3d> FixedLagSmoother::gyroBiasCovariance() const {
  const std::optional<Eigen::Matrix<double, 6, 6>> C = biasCovariance();
  if (!C) return std::nullopt;
  return Eigen::Matrix3d(C->topLeftCorner<3, 3>());
}

SmootherUpdate FixedLagSmoother::update(const imu::Preintegrator& pim, const Eigen::Isometry3d& T_world_imu_measured) {
  return update(pim, T_world_imu_measured,
                poseSqrtInformation(impl_->config.lidar_sigma_position, impl_->config.lidar_sigma_rotation));
}

SmootherUpdate FixedLagSmoother::update(const imu::Preintegrator& pim, const Eigen::Isometry3d& T_world_imu_measured,
                                        const Eigen::Matrix<double, 6, 6>& pose_sqrt_information,
                                        const std::optional<RelativePoseMeasurement>& relative) {
  if (!impl_->initialized) throw std::invalid_argument("FixedLagSmoother::update: not initialized");
  if (!T_world_imu_measured.matrix().allFinite() || !pose_sqrt_information.allFinite()) {
    throw std::invalid_argument("FixedLagSmoother::update: pose measurement or its information is not finite");
  }
  if (relative && (!relative->T_i_j.matrix().allFinite() || !relative->sqrt_information.allFinite())) {
    throw std::invalid_argument("FixedLagSmoother::update: relative pose or its information is not finite");
  }
  // Fails early (std::invalid_argument) on dt <= 0 or a singular covariance, before the window changes.
  const ImuPreintegrationFactor check(pim);
  (void)check;

  SmootherWindow& w = impl_->window;
  const SmootherWindow before = w;  // rolled back to on failure
  const WindowNode& newest = w.nodes.back();
  WindowNode node;
  node.set(pim.predict(newest.navState(), newest.imuBias()), newest.imuBias());
  node.pim = pim;
  node.pose_measured = T_world_imu_measured;
  node.pose_sqrt_information = pose_sqrt_information;
  if (relative) {
    node.relative_measured = relative->T_i_j;
    node.relative_sqrt_information = relative->sqrt_information;
  }
  w.nodes.push_back(std::move(node));

  SmootherUpdate result = impl_->solve(SmootherUpdate{});
  if (!result.ok) {
    w = before;
    result.state = w.nodes.back().navState();
    result.bias = w.nodes.back().imuBias();
  }
  result.states = static_cast<int>(w.nodes.size());
  return result;
}

SmootherUpdate FixedLagSmoother::Impl::solve(SmootherUpdate update) {
  ceres::Solver::Summary summary;
  {  // the problem points into the window's nodes: it must be gone before marginalisation drops one
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    window.buildProblem(problem, &manifold);
    ceres::Solver::Options options;
    // Dense QR: a window of ~10 states is ~160 parameters, and QR avoids squaring the condition number of
    // weights that span 1e0 (velocity prior) to 1e5 (bias random walk).
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = config.max_iterations;
    options.num_threads = 1;
    options.logging_type = ceres::SILENT;
    // The initial values (IMU prediction, previous solution) are close: start as Gauss-Newton, or the default
    // radius 1e4 holds the first steps back (measured: 8.5 iterations mean instead of 2.2).
    options.initial_trust_region_radius = 1e10;
    ceres::Solve(options, &problem, &summary);
  }
  update.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  update.initial_cost = summary.initial_cost;
  update.final_cost = summary.final_cost;

  if (!summary.IsSolutionUsable()) {
    update.failure = true;
    update.reason = "solver: " + summary.message;
    return update;
  }
  // The newest state first (LIO-SAM checks only it), then the rest of the window.
  for (auto node = window.nodes.rbegin(); node != window.nodes.rend(); ++node) {
    const std::string why = implausibility(*node, config);
    if (!why.empty()) {
      update.failure = true;
      update.reason = why;
      return update;
    }
  }
  while (static_cast<int>(window.nodes.size()) > config.window) {
    const std::string why = window.marginalizeFront();
    if (!why.empty()) {
      update.failure = true;
      update.reason = why;
      return update;
    }
  }
  update.ok = true;
  update.state = window.nodes.back().navState();
  update.bias = window.nodes.back().imuBias();
  return update;
}

imu::NavState FixedLagSmoother::state() const {
  if (!impl_->initialized) throw std::logic_error("FixedLagSmoother::state: not initialized");
  return impl_->window.nodes.back().navState();
}

imu::ImuBias FixedLagSmoother::bias() const {
  if (!impl_->initialized) throw std::logic_error("FixedLagSmoother::bias: not initialized");
  return impl_->window.nodes.back().imuBias();
}

bool FixedLagSmoother::initialized() const { return impl_->initialized; }
int FixedLagSmoother::size() const { return impl_->initialized ? static_cast<int>(impl_->window.nodes.size()) : 0; }

void FixedLagSmoother::reset() {
  impl_->initialized = false;
  impl_->window = SmootherWindow{};
}

const FixedLagSmoother::Config& FixedLagSmoother::config() const { return impl_->config; }

}  // namespace drover::backend
