// The newest frame's pose relative to the previous frame, with its covariance from the window's own information
// (every residual of the solve and the marginal prior, everything else Schur-complemented out): what the LIS's
// visual-odometry factor is weighted by (pipeline::VisualMotion with vis_fusion.window_covariance).
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <ceres/sized_cost_function.h>

#include "backend/pose_factors.hpp"
#include "backend/schur_marginalizer.hpp"
#include "geometry/so3.hpp"
#include "vio/window_frame.hpp"
#include "vio/window_residuals.hpp"

namespace drover::vio {
namespace {

// x held at x0 with sigma (a constant the solve did not estimate is conditioned on, not marginalised).
class ScalarPrior final : public ceres::SizedCostFunction<1, 1> {
 public:
  ScalarPrior(double x0, double sigma) : x0_(x0), weight_(1.0 / sigma) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    residuals[0] = weight_ * (parameters[0][0] - x0_);
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = weight_;
    return true;
  }

 private:
  double x0_, weight_;
};

constexpr double kConstantSigma = 1e-6;   // [m, rad, s] an extrinsic or time offset the solve holds constant

}  // namespace

std::optional<Eigen::Matrix<double, 6, 6>> SlidingWindowEstimator::newestRelativeCovariance() {
  if (frames_.size() < 2) return std::nullopt;
  backend::SchurMarginalizer m;
  const Residuals r = declareWindow(m, false);
  const std::vector<HeldDepth> depths = heldDepths(r);
  for (const HeldDepth& h : depths) m.addResidual(h.factor.get(), nullptr, {h.inverse_depth});
  std::vector<std::unique_ptr<ceres::CostFunction>> held;
  if (!config_.estimate_extrinsic) {
    held.push_back(std::make_unique<backend::PosePriorFactor>(
        T_imu_cam(), backend::poseSqrtInformation(kConstantSigma, kConstantSigma)));
    m.addResidual(held.back().get(), nullptr, {p_ic_, q_ic_});
  }
  if (!config_.estimate_time_offset) {
    held.push_back(std::make_unique<ScalarPrior>(td_[0], kConstantSigma));
    m.addResidual(held.back().get(), nullptr, {td_});
  }
  if (prior_) m.addResidual(prior_.get(), nullptr, prior_->blocks());
  for (auto& item : r.items) m.addResidual(item.cost.get(), item.loss, item.blocks);
  const Frame& a = *frames_[frames_.size() - 2];
  const Frame& b = *frames_.back();
  std::set<const double*> drop;
  for (const auto& f : frames_)
    for (const double* block : {static_cast<const double*>(f->v), static_cast<const double*>(f->bias)})
      drop.insert(block);
  for (const auto& f : frames_)
    if (f.get() != &a && f.get() != &b) drop.insert({f->p, f->q});
  drop.insert({p_ic_, q_ic_, td_});
  for (double* d : r.inverse_depths) drop.insert(d);
  const backend::MarginalResult result = m.marginalize(drop);
  // Kept in declaration order: a.p, a.q, b.p, b.q (12 tangent dimensions, right perturbations).
  if (!result.ok || result.kept.size() != 4 || result.rank < 12) return std::nullopt;
  const Eigen::MatrixXd A = result.sqrt_information.transpose() * result.sqrt_information;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return std::nullopt;
  const Eigen::MatrixXd cov = ldlt.solve(Eigen::MatrixXd::Identity(12, 12));
  // T_a_b = T_a^-1 T_b: dp_ab = R_a^T (dp_b - dp_a) + [p_ab]x dtheta_a; dtheta_ab = dtheta_b - R_ab^T dtheta_a.
  const Eigen::Isometry3d Ta = a.pose(), Tb = b.pose();
  const Eigen::Matrix3d Ra_t = Ta.linear().transpose();
  const Eigen::Matrix3d R_ab = Ra_t * Tb.linear();
  const Eigen::Vector3d p_ab = Ra_t * (Tb.translation() - Ta.translation());
  Eigen::Matrix<double, 6, 12> J = Eigen::Matrix<double, 6, 12>::Zero();
  J.block<3, 3>(0, 0) = -Ra_t;
  J.block<3, 3>(0, 3) = geometry::hat(p_ab);
  J.block<3, 3>(0, 6) = Ra_t;
  J.block<3, 3>(3, 3) = -R_ab.transpose();
  J.block<3, 3>(3, 9) = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 6, 6> out = J * cov * J.transpose();
  out = 0.5 * (out + out.transpose()).eval();
  if (!out.allFinite()) return std::nullopt;
  return out;
}

}  // namespace drover::vio
