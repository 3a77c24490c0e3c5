// PoseGraphConfig checks, loss names and the information conversions of the pose graph (no Ceres here).
#include <cmath>
#include <stdexcept>
#include <string>

#include "backend/pose_graph.hpp"

namespace drover::backend {

namespace {

bool positiveFinite(double x) { return std::isfinite(x) && x > 0; }

}  // namespace

std::string PoseGraphConfig::validate() const {
  if (max_iterations < 1) return "max_iterations = " + std::to_string(max_iterations) + " must be >= 1";
  if (!positiveFinite(function_tolerance))
    return "function_tolerance = " + std::to_string(function_tolerance) + " must be finite and > 0";
  if (!positiveFinite(gradient_tolerance))
    return "gradient_tolerance = " + std::to_string(gradient_tolerance) + " must be finite and > 0";
  if (!positiveFinite(parameter_tolerance))
    return "parameter_tolerance = " + std::to_string(parameter_tolerance) + " must be finite and > 0";
  if (!positiveFinite(initial_trust_region_radius))
    return "initial_trust_region_radius = " + std::to_string(initial_trust_region_radius) + " must be finite and > 0";
  if (!positiveFinite(loop_loss_scale))
    return "loop_loss_scale = " + std::to_string(loop_loss_scale) + " must be finite and > 0";
  if (threads < 1) return "threads = " + std::to_string(threads) + " must be >= 1";
  return "";
}

RobustLoss parseRobustLoss(const std::string& name) {
  if (name == "none") return RobustLoss::kNone;
  if (name == "huber") return RobustLoss::kHuber;
  if (name == "cauchy") return RobustLoss::kCauchy;
  throw std::invalid_argument("unknown loss '" + name + "' (expected none, huber or cauchy)");
}

std::string robustLossName(RobustLoss loss) {
  switch (loss) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "unknown";
}

Matrix6d informationFromRightPerturbation(const Matrix6d& information_rho_phi, const Eigen::Matrix3d& R_m) {
  // r = S xi with S = diag(R_m, I), so info_r = S^-T info_xi S^-1 = S info_xi S^T (S is orthogonal).
  Matrix6d S = Matrix6d::Identity();
  S.topLeftCorner<3, 3>() = R_m;
  return S * information_rho_phi * S.transpose();
}

}  // namespace drover::backend
