#include "backend/schur_marginalizer.hpp"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <chrono>
#include <iostream>
#include <limits>
#include <memory>
#include <random>

#include "marginal_test_util.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

void solve(ceres::Problem& problem) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = options.gradient_tolerance = options.parameter_tolerance = 1e-16;
  options.max_num_iterations = 100;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
}

ceres::Problem::Options borrowing() {
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return po;
}

}  // namespace

TEST(SchurMarginalizer, LinearChainPriorIsTheClosedFormGaussianMarginalAndTheReducedProblemSolvesTheSame) {
  // prior(x0) - (x0, x1) - (x1, x2), x1 dropped; a later factor (x2, x3) arrives after the marginalisation.
  std::mt19937 rng(1);
  LinearProblem p;
  for (int i = 0; i < 3; ++i) p.addBlock(randomVec(rng, 2));
  p.addCost(rng, 2, {0});
  p.addCost(rng, 3, {0, 1});
  p.addCost(rng, 3, {1, 2});
  std::vector<double> x3 = {0.3, -0.7};
  const LinearCost later({randomMatrix(rng, 2, 2), randomMatrix(rng, 2, 2)}, randomVec(rng, 2));
  SchurMarginalizer marg = p.marginalizer();
  marg.addBlock(x3.data(), 2, nullptr);  // declared, but no residual handed over touches it
  const MarginalResult m = marg.marginalize({p.x[1].data()});
  ASSERT_TRUE(m.ok) << m.reason;
  ASSERT_EQ(m.kept, (std::vector<double*>{p.x[0].data(), p.x[2].data()}));
  EXPECT_EQ(m.tangent_sizes, (std::vector<int>{2, 2}));
  EXPECT_EQ(m.linearization[1], p.x[2]);
  expectExactMarginal(p, {0, 2}, m, 1e-10);

  std::vector<std::vector<double>> full_x = p.x, reduced_x = p.x;
  full_x.push_back(x3);
  reduced_x.push_back(x3);
  ceres::Problem full(borrowing()), reduced(borrowing());
  for (std::size_t i = 0; i < p.costs.size(); ++i) {
    std::vector<double*> blocks;
    for (int b : p.cost_blocks[i]) blocks.push_back(full_x[b].data());
    full.AddResidualBlock(p.costs[i].get(), nullptr, blocks);
  }
  full.AddResidualBlock(const_cast<LinearCost*>(&later), nullptr, full_x[2].data(), full_x[3].data());
  MarginalResult moved = m;
  moved.kept = {reduced_x[0].data(), reduced_x[2].data()};  // the same prior on the copies
  MarginalPriorFactor prior(moved);
  reduced.AddResidualBlock(&prior, nullptr, prior.blocks());
  reduced.AddResidualBlock(const_cast<LinearCost*>(&later), nullptr, reduced_x[2].data(), reduced_x[3].data());
  solve(full);
  solve(reduced);
  for (int b : {0, 2, 3}) {
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(reduced_x[b][i], full_x[b][i], 1e-9) << "block " << b;
  }
}

TEST(SchurMarginalizer, ReproducesMarginalizeStateOnTheImuChainWithQuaternionBlocks) {
  std::mt19937 rng(4);
  ImuChain chain(rng);
  const MarginalPrior existing = marginalizeState(chain.terms, chain.x0(), chain.x1());
  ASSERT_TRUE(existing.ok) << existing.reason;
  const auto x0 = chain.x0();
  const MarginalResult m = chain.marginalizer().marginalize({x0[0], x0[1], x0[2], x0[3]});
  ASSERT_TRUE(m.ok) << m.reason;
  const auto x1 = chain.x1();
  EXPECT_EQ(m.kept, std::vector<double*>(x1.begin(), x1.end()));
  EXPECT_EQ(m.tangent_sizes, (std::vector<int>{3, 3, 3, 6}));
  EXPECT_EQ(m.rank, 15);
  EXPECT_EQ(existing.rank, 15);
  const MatrixXd A_existing = existing.sqrt_information.transpose() * existing.sqrt_information;
  const VectorXd b_existing = existing.sqrt_information.transpose() * existing.offset;
  ASSERT_GT(b_existing.norm(), 1.0) << "the chain must be linearised away from its optimum";
  // Forming A cancels ~8 digits (bias random-walk information ~1e10 in H_kk, ~1e2 left in A), so in A's own units
  // either computation carries ~1e-8 of rounding (measured: 3e-8 and 2e-9 against a long-double Schur complement).
  EXPECT_LT(scaledError(informationOf(m), A_existing), 1e-6);
  EXPECT_LT(scaledGradientError(gradientOf(m), b_existing, A_existing), 1e-7);
}

TEST(SchurMarginalizer, GaugeFreedomAndAnUnconstrainedDroppedBlockGiveAFiniteRankDeficientPrior) {
  // Only relative factors x1 - x0 and x2 - x1 (no prior: a translation gauge), plus a dropped block u touched by a
  // factor with a zero Jacobian (H_mm singular). Marginalising x1 and u leaves the relative measurement x2 - x0 with
  // covariance S01 + S12: A = [W -W; -W W], W = (S01 + S12)^-1, rank 2 of 4.
  std::mt19937 rng(7);
  std::vector<std::vector<double>> x(4, std::vector<double>(2));
  for (auto& b : x) Eigen::Map<Eigen::Vector2d>(b.data()) = randomVec(rng, 2);
  const Eigen::Matrix2d L01 = randomMatrix(rng, 2, 2), L12 = randomMatrix(rng, 2, 2);
  LinearCost f01({-L01, L01}, randomVec(rng, 2)), f12({-L12, L12}, randomVec(rng, 2));
  LinearCost fu({MatrixXd::Zero(2, 2)}, randomVec(rng, 2));
  SchurMarginalizer marg;
  for (auto& b : x) marg.addBlock(b.data(), 2, nullptr);
  marg.addResidual(&f01, nullptr, {x[0].data(), x[1].data()});
  marg.addResidual(&f12, nullptr, {x[1].data(), x[2].data()});
  marg.addResidual(&fu, nullptr, {x[3].data()});
  const MarginalResult m = marg.marginalize({x[1].data(), x[3].data()});
  ASSERT_TRUE(m.ok) << m.reason;
  EXPECT_EQ(m.rank, 2);
  ASSERT_EQ(m.sqrt_information.rows(), 2);
  ASSERT_EQ(m.sqrt_information.cols(), 4);
  EXPECT_TRUE(m.sqrt_information.allFinite() && m.offset.allFinite());
  const Eigen::Matrix2d W = ((L01.transpose() * L01).inverse() + (L12.transpose() * L12).inverse()).inverse();
  MatrixXd expected(4, 4);
  expected << W, -W, -W, W;
  EXPECT_LT(relativeError(informationOf(m), expected), 1e-10);
  // The prior cannot see a common translation of x0 and x2.
  Eigen::Vector4d translation;
  translation << 1, 0, 1, 0;
  EXPECT_LT((m.sqrt_information * translation).norm(), 1e-8 * m.sqrt_information.norm());
}

TEST(SchurMarginalizer, WeakButRealInformationSurvivesBesideInformationTenOrdersLarger) {
  // A gyro-bias-like block with information 1e10 and a velocity-like block with information 1 (1 m/s), coupled
  // through a dropped block: the rank cut is scale-free (Jacobi-scaled), so both directions stay. An unscaled
  // relative threshold of 1e-8 would drop the weak one.
  // A third kept block with information 1e-22 of the largest is below the rounding level of H and is left out.
  std::vector<double> strong = {0.1}, weak = {0.2}, dropped = {0.3}, noise = {0.4};
  LinearCost on_strong({MatrixXd::Constant(1, 1, 1e5), MatrixXd::Constant(1, 1, 1e-6)}, VectorXd::Constant(1, 0.5));
  LinearCost link({MatrixXd::Constant(1, 1, 1.0), MatrixXd::Constant(1, 1, -1.0)}, VectorXd::Zero(1));
  LinearCost on_dropped({MatrixXd::Constant(1, 1, 1.0)}, VectorXd::Zero(1));
  SchurMarginalizer marg;
  for (double* b : {strong.data(), weak.data(), dropped.data(), noise.data()}) marg.addBlock(b, 1, nullptr);
  marg.addResidual(&on_strong, nullptr, {strong.data(), noise.data()});
  marg.addResidual(&link, nullptr, {weak.data(), dropped.data()});
  marg.addResidual(&on_dropped, nullptr, {dropped.data()});
  const MarginalResult m = marg.marginalize({dropped.data()});
  ASSERT_TRUE(m.ok) << m.reason;
  EXPECT_EQ(m.rank, 2);
  // weak - dropped = 0 and dropped = 0, both with unit information: weak's marginal information is 1/2.
  const MatrixXd A = informationOf(m);
  EXPECT_NEAR(A(0, 0), 1e10, 1e-6 * 1e10);
  EXPECT_NEAR(A(1, 1), 0.5, 1e-9);
  EXPECT_NEAR(A(0, 1), 0.0, 1e-9);
  EXPECT_EQ(A.row(2).norm(), 0.0);
  EXPECT_TRUE(m.sqrt_information.allFinite() && m.offset.allFinite());
}

TEST(SchurMarginalizer, PriorFactorResidualIsTheOffsetAtTheLinearisationPointAndItsJacobiansAreNumerical) {
  std::mt19937 rng(5);
  ImuChain chain(rng);
  const auto x0 = chain.x0();
  const MarginalResult m = chain.marginalizer().marginalize({x0[0], x0[1], x0[2], x0[3]});
  ASSERT_TRUE(m.ok) << m.reason;
  const MarginalPriorFactor prior(m);
  EXPECT_EQ(prior.num_residuals(), m.rank);
  EXPECT_EQ(prior.parameter_block_sizes(), (std::vector<int32_t>{3, 4, 3, 6}));
  std::vector<Param> at_lin;
  for (std::size_t k = 0; k < 4; ++k) at_lin.push_back({m.linearization[k], k == 1});
  EXPECT_LT((evaluate(prior, at_lin) - m.offset).norm(), 1e-12 * m.offset.norm());
  // Far from the linearisation point (0.3 rad), where d Log / d dtheta is no longer the identity.
  std::vector<Param> away = at_lin;
  for (int k : {0, 2, 3}) {
    for (double& v : away[k].x) v += 0.2 * std::uniform_real_distribution<double>(-1, 1)(rng);
  }
  away[1] = quaternionParam(Eigen::Map<const Eigen::Quaterniond>(at_lin[1].x.data()) *
                            geometry::expQuat(Eigen::Vector3d(0.2, -0.15, 0.1)));
  EXPECT_LT(tangentJacobianError(prior, away), 1e-6);
  EXPECT_LT(ambientJacobianError(prior, away), 1e-6);
}

TEST(SchurMarginalizer, PriorFactorTangentJacobianIsNumericalForAManifoldWithoutAClosedForm) {
  // ceres::EigenQuaternionManifold (left perturbation) goes through the central-difference T of Minus.
  std::mt19937 rng(6);
  const ceres::EigenQuaternionManifold manifold;
  std::vector<double> q = {0.1, -0.2, 0.3, 0.9}, y = {0.3, -0.4};
  Eigen::Map<Eigen::Vector4d>(q.data()).normalize();
  LinearCost link({randomMatrix(rng, 4, 4), randomMatrix(rng, 4, 2)}, randomVec(rng, 4));
  LinearCost on_y({randomMatrix(rng, 2, 2)}, randomVec(rng, 2));
  SchurMarginalizer marg;
  marg.addBlock(q.data(), 4, &manifold);
  marg.addBlock(y.data(), 2, nullptr);
  marg.addResidual(&link, nullptr, {q.data(), y.data()});
  marg.addResidual(&on_y, nullptr, {y.data()});
  const MarginalResult m = marg.marginalize({y.data()});
  ASSERT_TRUE(m.ok) << m.reason;
  EXPECT_EQ(m.rank, 3);
  const MarginalPriorFactor prior(m);
  std::vector<double> x(4);
  const Eigen::Vector3d step(0.25, -0.1, 0.2);
  manifold.Plus(q.data(), step.data(), x.data());
  std::vector<RowMatrix> J;
  evaluate(prior, {{x}}, &J);
  RowMatrix P(4, 3);
  manifold.PlusJacobian(x.data(), P.data());
  const MatrixXd analytic = J[0] * P;
  MatrixXd numeric(3, 3);
  for (int j = 0; j < 3; ++j) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    std::vector<double> xp(4), xm(4);
    d(j) = 1e-6;
    manifold.Plus(x.data(), d.data(), xp.data());
    d(j) = -1e-6;
    manifold.Plus(x.data(), d.data(), xm.data());
    numeric.col(j) = (evaluate(prior, {{xp}}) - evaluate(prior, {{xm}})) / 2e-6;
  }
  EXPECT_LT(relativeError(analytic, numeric), 1e-6);
}

TEST(SchurMarginalizer, RobustLossesAreAppliedAsCeresAppliesThem) {
  // With nothing dropped the prior is the full Gauss-Newton model: L^T L = J^T J and L^T offset = J^T r, which
  // Ceres' Problem::Evaluate gives (tangent space, loss-corrected). Huber in its outlier range (sqrt(rho') only),
  // TolerantLoss (rho'' > 0: the Triggs correction), Cauchy.
  std::mt19937 rng(9);
  ImuChain chain(rng);
  const ceres::HuberLoss huber(1e-3);
  // TolerantLoss centred on the IMU residual's |r|^2 = s: rho' = 1/2, 1 + 2 s rho'' / rho' = 2, a large correction.
  const auto imu_blocks = chain.all();
  const std::array<const double*, 7> imu_params = {imu_blocks[0], imu_blocks[1], imu_blocks[2], imu_blocks[3],
                                                   imu_blocks[4], imu_blocks[5], imu_blocks[6]};
  Eigen::Matrix<double, 9, 1> r_imu;
  ASSERT_TRUE(chain.terms[2].cost->Evaluate(imu_params.data(), r_imu.data(), nullptr));
  const ceres::TolerantLoss tolerant(r_imu.squaredNorm(), r_imu.squaredNorm());
  const ceres::CauchyLoss cauchy(0.1);
  const std::vector<const ceres::LossFunction*> losses = {&huber, nullptr, &tolerant, &cauchy};
  const MarginalResult full = chain.marginalizer(losses, 0.0).marginalize({});
  ASSERT_TRUE(full.ok) << full.reason;
  ASSERT_EQ(full.rank, 30);

  ceres::Problem problem(borrowing());
  const auto blocks = chain.all();
  for (std::size_t i = 0; i < chain.terms.size(); ++i) {
    std::vector<double*> ptrs;
    for (int b : chain.terms[i].blocks) ptrs.push_back(blocks[b]);
    problem.AddResidualBlock(const_cast<ceres::CostFunction*>(chain.terms[i].cost),
                             const_cast<ceres::LossFunction*>(losses[i]), ptrs);
  }
  problem.SetManifold(chain.q0.data(), &chain.manifold);
  problem.SetManifold(chain.q1.data(), &chain.manifold);
  ceres::Problem::EvaluateOptions options;
  options.parameter_blocks.assign(blocks.begin(), blocks.end());
  std::vector<double> gradient;
  ceres::CRSMatrix crs;
  ASSERT_TRUE(problem.Evaluate(options, nullptr, nullptr, &gradient, &crs));
  MatrixXd J = MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int i = crs.rows[row]; i < crs.rows[row + 1]; ++i) J(row, crs.cols[i]) = crs.values[i];
  }
  ASSERT_EQ(J.cols(), 30);
  const MatrixXd H = J.transpose() * J;
  EXPECT_LT(scaledError(informationOf(full), H), 1e-9);
  EXPECT_LT(scaledGradientError(gradientOf(full), Eigen::Map<const VectorXd>(gradient.data(), 30), H), 1e-9);
  // The losses must matter for this test to mean anything.
  const MarginalResult plain = chain.marginalizer({}, 0.0).marginalize({});
  EXPECT_GT(scaledGradientError(gradientOf(plain), gradientOf(full), H), 1e-2);
  EXPECT_GT(scaledError(informationOf(plain), H), 1e-2);
}

TEST(SchurMarginalizer, MarginalisingTwiceThroughThePriorFactorEqualsMarginalisingOnce) {
  // The sliding-window pattern: the previous prior is one of the residuals of the next marginalisation.
  // prior(x0) - (x0, x1) - (x1, x2): dropping x0, then x1 (with the first prior) equals dropping {x0, x1} at once.
  std::mt19937 rng(11);
  LinearProblem p;
  for (int i = 0; i < 3; ++i) p.addBlock(randomVec(rng, 3));
  p.addCost(rng, 3, {0});
  p.addCost(rng, 4, {0, 1});
  p.addCost(rng, 4, {1, 2});
  SchurMarginalizer once = p.marginalizer();
  const MarginalResult direct = once.marginalize({p.x[0].data(), p.x[1].data()});
  SchurMarginalizer first;
  for (int b : {0, 1}) first.addBlock(p.x[b].data(), 3, nullptr);
  first.addResidual(p.costs[0].get(), nullptr, {p.x[0].data()});
  first.addResidual(p.costs[1].get(), nullptr, {p.x[0].data(), p.x[1].data()});
  const MarginalPriorFactor prior1(first.marginalize({p.x[0].data()}));
  SchurMarginalizer second;
  for (int b : {1, 2}) second.addBlock(p.x[b].data(), 3, nullptr);
  second.addResidual(&prior1, nullptr, prior1.blocks());
  second.addResidual(p.costs[2].get(), nullptr, {p.x[1].data(), p.x[2].data()});
  const MarginalResult chained = second.marginalize({p.x[1].data()});
  ASSERT_TRUE(direct.ok && chained.ok) << direct.reason << chained.reason;
  ASSERT_EQ(chained.kept, direct.kept);
  EXPECT_LT(relativeError(informationOf(chained), informationOf(direct)), 1e-10);
  EXPECT_LT(relativeError(gradientOf(chained), gradientOf(direct)), 1e-10);
  expectExactMarginal(p, {2}, chained, 1e-10);
}

namespace {
class FailingCost final : public ceres::SizedCostFunction<1, 2> {
 public:
  bool Evaluate(double const* const*, double*, double**) const override { return false; }
};
class NanCost final : public ceres::SizedCostFunction<1, 2> {
 public:
  bool Evaluate(double const* const*, double* r, double** j) const override {
    r[0] = std::numeric_limits<double>::quiet_NaN();
    if (j && j[0]) j[0][0] = j[0][1] = 1.0;
    return true;
  }
};
}  // namespace

TEST(SchurMarginalizer, FailedOrNonFiniteEvaluationIsNotOkAndMisuseThrows) {
  std::vector<double> a = {1, 2}, b = {3, 4}, c = {5, 6};
  LinearCost link({MatrixXd::Identity(2, 2), MatrixXd::Identity(2, 2)}, VectorXd::Zero(2));
  FailingCost failing;
  NanCost nan;
  for (const ceres::CostFunction* bad : std::vector<const ceres::CostFunction*>{&failing, &nan}) {
    SchurMarginalizer marg;
    marg.addBlock(a.data(), 2, nullptr);
    marg.addBlock(b.data(), 2, nullptr);
    marg.addResidual(&link, nullptr, {a.data(), b.data()});
    marg.addResidual(bad, nullptr, {a.data()});
    const MarginalResult m = marg.marginalize({a.data()});
    EXPECT_FALSE(m.ok);
    EXPECT_NE(m.reason.find("residual block 1"), std::string::npos) << m.reason;
    EXPECT_THROW(MarginalPriorFactor{m}, std::invalid_argument);
  }
  SchurMarginalizer marg;
  marg.addBlock(a.data(), 2, nullptr);
  marg.addBlock(b.data(), 2, nullptr);
  EXPECT_THROW(marg.addResidual(&link, nullptr, {a.data(), c.data()}), std::invalid_argument);  // c undeclared
  EXPECT_THROW(marg.addResidual(&link, nullptr, {a.data(), a.data()}), std::invalid_argument);  // repeated
  EXPECT_THROW(marg.addResidual(&link, nullptr, {a.data()}), std::invalid_argument);            // count
  EXPECT_THROW(marg.addBlock(a.data(), 3, nullptr), std::invalid_argument);                     // redeclared
  const RightQuaternionManifold quaternion;
  EXPECT_THROW(marg.addBlock(c.data(), 2, &quaternion), std::invalid_argument);                 // manifold size
  marg.addResidual(&link, nullptr, {a.data(), b.data()});
  EXPECT_THROW(marg.marginalize({c.data()}), std::invalid_argument);
  const MarginalResult nothing_kept = marg.marginalize({a.data(), b.data()});
  EXPECT_FALSE(nothing_kept.ok);
  EXPECT_FALSE(nothing_kept.reason.empty());
}

TEST(SchurMarginalizer, VioSizedWindowGivesTheClosedFormMarginal) {
  // 11 frames x 15, a 6-dim extrinsic, 150 inverse depths anchored in frame 0, each seen in 3 later frames (2-row
  // residuals on depth, frame 0, frame k, extrinsic); frame 0 and the depths are dropped (165 of 321 dimensions).
  std::mt19937 rng(10);
  LinearProblem p;
  std::vector<int> frames, depths;
  for (int i = 0; i < 11; ++i) frames.push_back(p.addBlock(randomVec(rng, 15)));
  const int extrinsic = p.addBlock(randomVec(rng, 6));
  for (int j = 0; j < 150; ++j) depths.push_back(p.addBlock(randomVec(rng, 1)));
  p.addCost(rng, 15, {frames[0]});
  p.addCost(rng, 15, {frames[0], frames[1]});
  std::uniform_int_distribution<int> later(1, 10);
  for (int j = 0; j < 150; ++j) {
    for (int obs = 0; obs < 3; ++obs) p.addCost(rng, 2, {depths[j], frames[0], frames[later(rng)], extrinsic});
  }
  SchurMarginalizer marg = p.marginalizer();
  std::set<const double*> drop = {p.x[frames[0]].data()};
  for (int d : depths) drop.insert(p.x[d].data());
  const auto start = std::chrono::steady_clock::now();
  const MarginalResult m = marg.marginalize(drop);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cout << "marginalize, 321 dims (165 dropped), 452 residual blocks: " << ms << " ms\n";
  ASSERT_TRUE(m.ok) << m.reason;
  EXPECT_EQ(m.kept.size(), 11u);
  std::vector<int> kept(frames.begin() + 1, frames.end());
  kept.push_back(extrinsic);
  expectExactMarginal(p, kept, m, 1e-7);
  // Deterministic: the same input gives bit-identical output.
  const MarginalResult again = marg.marginalize(drop);
  EXPECT_EQ(again.sqrt_information, m.sqrt_information);
  EXPECT_EQ(again.offset, m.offset);
}
