#include "backend/smoother_window.hpp"

#include <memory>
#include <vector>

#include "backend/imu_factors.hpp"
#include "backend/state_prior_factor.hpp"
#include "geometry/se3.hpp"

namespace drover::backend {

void WindowNode::set(const imu::NavState& state, const imu::ImuBias& bias) {
  t = state.t;
  Eigen::Map<Eigen::Vector3d>(p.data()) = state.T_world_imu.translation();
  Eigen::Map<Eigen::Quaterniond>(q.data()) = Eigen::Quaterniond(state.T_world_imu.linear()).normalized();
  Eigen::Map<Eigen::Vector3d>(v.data()) = state.v_world;
  Eigen::Map<Vector6d>(b.data()) << bias.gyro, bias.acc;
}

imu::NavState WindowNode::navState() const {
  imu::NavState s;
  s.t = t;
  s.T_world_imu = geometry::makeIsometry(Eigen::Map<const Eigen::Quaterniond>(q.data()).normalized(),
                                         Eigen::Map<const Eigen::Vector3d>(p.data()));
  s.v_world = Eigen::Map<const Eigen::Vector3d>(v.data());
  return s;
}

imu::ImuBias WindowNode::imuBias() const {
  imu::ImuBias bias;
  bias.gyro = Eigen::Map<const Eigen::Vector3d>(b.data());
  bias.acc = Eigen::Map<const Eigen::Vector3d>(b.data() + 3);
  return bias;
}

StatePoint WindowNode::statePoint() const {
  StatePoint s;
  s.p_world = Eigen::Map<const Eigen::Vector3d>(p.data());
  s.q_world_imu = Eigen::Map<const Eigen::Quaterniond>(q.data()).normalized();
  s.v_world = Eigen::Map<const Eigen::Vector3d>(v.data());
  s.bias = Eigen::Map<const Vector6d>(b.data());
  return s;
}

void SmootherWindow::buildProblem(ceres::Problem& problem, ceres::Manifold* manifold) {
  for (WindowNode& node : nodes) {
    problem.AddParameterBlock(node.p.data(), 3);
    problem.AddParameterBlock(node.q.data(), 4, manifold);
    problem.AddParameterBlock(node.v.data(), 3);
    problem.AddParameterBlock(node.b.data(), 6);
  }
  WindowNode& front = nodes.front();
  problem.AddResidualBlock(new NavStatePriorFactor(prior.linearization, prior.sqrt_information, prior.offset),
                           nullptr, front.p.data(), front.q.data(), front.v.data(), front.b.data());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    WindowNode& node = nodes[k];
    if (node.pose_measured) {
      problem.AddResidualBlock(new PosePriorFactor(*node.pose_measured, node.pose_sqrt_information), nullptr,
                               node.p.data(), node.q.data());
    }
    if (k == 0) continue;
    WindowNode& prev = nodes[k - 1];
    if (node.relative_measured) {
      problem.AddResidualBlock(new RelativePoseFactor(*node.relative_measured, node.relative_sqrt_information),
                               nullptr, prev.p.data(), prev.q.data(), node.p.data(), node.q.data());
    }
    if (!node.pim) continue;
    problem.AddResidualBlock(new ImuPreintegrationFactor(*node.pim), nullptr, prev.p.data(), prev.q.data(),
                             prev.v.data(), prev.b.data(), node.p.data(), node.q.data(), node.v.data());
    problem.AddResidualBlock(new BiasRandomWalkFactor(gyro_random_walk, acc_random_walk, node.pim->deltaTime()),
                             nullptr, prev.b.data(), node.b.data());
  }
}

std::string SmootherWindow::marginalizeFront() {
  if (nodes.size() < 2) return "marginalisation: fewer than two states";
  WindowNode& m = nodes[0];
  WindowNode& r = nodes[1];
  // Every factor that touches the dropped state; block indices 0..3 = (p, q, v, b) of m, 4..7 = those of r.
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<MarginalizationTerm> terms;
  const auto add = [&](ceres::CostFunction* cost, std::vector<int> blocks) {
    costs.emplace_back(cost);
    terms.push_back({cost, std::move(blocks)});
  };
  add(new NavStatePriorFactor(prior.linearization, prior.sqrt_information, prior.offset), {0, 1, 2, 3});
  if (m.pose_measured) add(new PosePriorFactor(*m.pose_measured, m.pose_sqrt_information), {0, 1});
  if (r.pim) {
    add(new ImuPreintegrationFactor(*r.pim), {0, 1, 2, 3, 4, 5, 6});
    add(new BiasRandomWalkFactor(gyro_random_walk, acc_random_walk, r.pim->deltaTime()), {3, 7});
  }
  if (r.relative_measured) add(new RelativePoseFactor(*r.relative_measured, r.relative_sqrt_information), {0, 1, 4, 5});
  const MarginalPrior result = marginalizeState(terms, m.blocks(), r.blocks());
  if (!result.ok) return result.reason;
  prior = {result.linearization, result.sqrt_information, result.offset};
  r.pim.reset();  // its factors now live in the prior
  r.relative_measured.reset();
  nodes.pop_front();
  return {};
}

}  // namespace drover::backend
