#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "backend/imu_factors.hpp"
#include "backend/marginalization.hpp"
#include "backend/pose_factors.hpp"
#include "backend/quaternion_manifold.hpp"
#include "factor_test_util.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

// Two navigation states as parameter blocks (p, q, v, b).
struct TwoStates {
  std::array<double, 3> p0{}, v0{}, p1{}, v1{};
  std::array<double, 4> q0{0, 0, 0, 1}, q1{0, 0, 0, 1};
  std::array<double, 6> b0{}, b1{};
  std::array<double*, 4> x0() { return {p0.data(), q0.data(), v0.data(), b0.data()}; }
  std::array<double*, 4> x1() { return {p1.data(), q1.data(), v1.data(), b1.data()}; }
};

struct Chain {
  imu::Preintegrator pim{imu::ImuBias{}, imu::PreintegrationConfig{}};
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<MarginalizationTerm> terms;
  Chain() {
    for (int k = 0; k < 40; ++k) pim.integrate({0.1, -0.2, 0.3}, {0.5, 0.2, 9.9}, 0.005);
    StatePoint origin;
    Vector15d inv_sigma = Vector15d::Constant(10.0);
    add(new NavStatePriorFactor(origin, inv_sigma.asDiagonal()), {0, 1, 2, 3});
    add(new PosePriorFactor(Eigen::Isometry3d::Identity(), poseSqrtInformation(0.05, 0.01)), {0, 1});
    add(new ImuPreintegrationFactor(pim), {0, 1, 2, 3, 4, 5, 6});
    add(new BiasRandomWalkFactor(2e-5, 3e-4, pim.deltaTime()), {3, 7});
  }
  void add(ceres::CostFunction* c, std::vector<int> blocks) {
    costs.emplace_back(c);
    terms.push_back({c, std::move(blocks)});
  }
  // min over x0 of 0.5 |r(x0, x1)|^2 with x1 held fixed (starts from the given x0, which it overwrites).
  double minimumOverX0(TwoStates& s) const {
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    RightQuaternionManifold manifold;
    std::array<double*, 8> blocks;
    const auto x0 = s.x0(), x1 = s.x1();
    std::copy(x0.begin(), x0.end(), blocks.begin());
    std::copy(x1.begin(), x1.end(), blocks.begin() + 4);
    for (const auto& t : terms) {
      std::vector<double*> ptrs;
      for (int b : t.blocks) ptrs.push_back(blocks[b]);
      problem.AddResidualBlock(const_cast<ceres::CostFunction*>(t.cost), nullptr, ptrs);
    }
    problem.SetManifold(s.q0.data(), &manifold);
    for (double* b : x1) {
      if (problem.HasParameterBlock(b)) problem.SetParameterBlockConstant(b);
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = 1e-14;
    options.gradient_tolerance = 1e-14;
    options.parameter_tolerance = 1e-14;
    options.max_num_iterations = 50;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    EXPECT_TRUE(summary.IsSolutionUsable());
    return summary.final_cost;
  }
};

double priorCost(const MarginalPrior& m, TwoStates s) {
  const NavStatePriorFactor prior(m.linearization, m.sqrt_information, m.offset);
  const auto x1 = s.x1();
  Vector15d r;
  prior.Evaluate(const_cast<double const* const*>(x1.data()), r.data(), nullptr);
  return 0.5 * r.squaredNorm();
}


// x1 moved by a random tangent step of the given scales (position/velocity/rotation, gyro bias, acc bias).
TwoStates moved(const TwoStates& s, std::mt19937& rng, double scale) {
  TwoStates m = s;
  Eigen::Map<Eigen::Vector3d>(m.p1.data()) += randomVector(rng, scale);
  Eigen::Map<Eigen::Vector3d>(m.v1.data()) += randomVector(rng, scale);
  Eigen::Map<Eigen::Quaterniond>(m.q1.data()) =
      Eigen::Map<Eigen::Quaterniond>(m.q1.data()) * geometry::expQuat(randomVector(rng, scale));
  Eigen::Map<Vector6d>(m.b1.data()) += (Vector6d() << randomVector(rng, 0.1 * scale), randomVector(rng, scale)).finished();
  return m;
}

// prior(x1') - prior(x1) against min_x0 cost(x0, x1') - min_x0 cost(x0, x1) for random steps of x1, to
// tolerance * max(|exact|, typical), typical the cost change such steps make.
void expectPriorMatchesMinimum(const Chain& chain, const TwoStates& s, std::mt19937& rng, double scale,
                               double tolerance, double typical) {
  const MarginalPrior m = marginalizeState(chain.terms, TwoStates(s).x0(), TwoStates(s).x1());
  ASSERT_TRUE(m.ok) << m.reason;
  EXPECT_EQ(m.rank, 15);
  TwoStates base = s;
  const double c_base = chain.minimumOverX0(base), p_base = priorCost(m, base);
  double largest = 0;
  for (int trial = 0; trial < 5; ++trial) {
    TwoStates x = moved(s, rng, scale);
    const double model = priorCost(m, x) - p_base, exact = chain.minimumOverX0(x) - c_base;
    largest = std::max(largest, std::abs(exact));
    EXPECT_NEAR(model, exact, tolerance * std::max(std::abs(exact), typical)) << "trial " << trial;
  }
  EXPECT_GT(largest, typical) << "the steps must change the cost noticeably";
}

}  // namespace

TEST(Marginalization, SchurPriorEqualsTheMinimumOverTheDroppedStateToSecondOrderAtAConsistentPoint) {
  // All dropped factors are zero at x0 = origin, x1 = the IMU prediction: the Gauss-Newton model is then exact to
  // second order, so the prior's quadratic matches the true marginal cost up to third-order terms.
  const Chain chain;
  TwoStates s;
  const imu::NavState x1 = chain.pim.predict(imu::NavState{}, imu::ImuBias{});
  Eigen::Map<Eigen::Vector3d>(s.p1.data()) = x1.T_world_imu.translation();
  Eigen::Map<Eigen::Quaterniond>(s.q1.data()) = Eigen::Quaterniond(x1.T_world_imu.linear());
  Eigen::Map<Eigen::Vector3d>(s.v1.data()) = x1.v_world;
  std::mt19937 rng(3);
  expectPriorMatchesMinimum(chain, s, rng, 1e-3, 1e-3, 1e-3);
}

TEST(Marginalization, SchurPriorCarriesTheGradientWhenLinearisedAwayFromTheOptimum) {
  // Away from the optimum the prior's offset carries the gradient b: small steps change both costs alike.
  const Chain chain;
  TwoStates s;
  std::mt19937 rng(4);
  const imu::NavState x1 = chain.pim.predict(imu::NavState{}, imu::ImuBias{});
  Eigen::Map<Eigen::Vector3d>(s.p0.data()) = randomVector(rng, 2e-3);
  Eigen::Map<Eigen::Quaterniond>(s.q0.data()) = geometry::expQuat(randomVector(rng, 1e-3));
  Eigen::Map<Eigen::Vector3d>(s.p1.data()) = x1.T_world_imu.translation() + randomVector(rng, 2e-3);
  Eigen::Map<Eigen::Quaterniond>(s.q1.data()) =
      Eigen::Quaterniond(x1.T_world_imu.linear()) * geometry::expQuat(randomVector(rng, 1e-3));
  Eigen::Map<Eigen::Vector3d>(s.v1.data()) = x1.v_world + randomVector(rng, 2e-3);
  expectPriorMatchesMinimum(chain, s, rng, 1e-5, 1e-2, 1e-4);
}
