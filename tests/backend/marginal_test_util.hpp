#pragma once
// Shared fixtures of the marginalisation tests: linear-Gaussian problems with a closed-form marginal, and the
// two-state IMU chain of test_marginalization.cpp as blocks of a SchurMarginalizer.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <memory>
#include <random>
#include <vector>

#include "backend/imu_factors.hpp"
#include "backend/marginalization.hpp"
#include "backend/pose_factors.hpp"
#include "backend/quaternion_manifold.hpp"
#include "backend/schur_marginalizer.hpp"
#include "factor_test_util.hpp"

namespace drover::backend::test {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// r = sum_k A_k x_k - c: a linear-Gaussian measurement (A_k already whitened).
class LinearCost final : public ceres::CostFunction {
 public:
  LinearCost(std::vector<MatrixXd> A, VectorXd c) : A_(std::move(A)), c_(std::move(c)) {
    set_num_residuals(static_cast<int>(c_.size()));
    for (const auto& a : A_) mutable_parameter_block_sizes()->push_back(static_cast<int>(a.cols()));
  }
  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    Eigen::Map<VectorXd> r(residuals, c_.size());
    r = -c_;
    for (std::size_t k = 0; k < A_.size(); ++k) {
      r += A_[k] * Eigen::Map<const VectorXd>(x[k], A_[k].cols());
      if (jacobians && jacobians[k]) Eigen::Map<RowMatrix>(jacobians[k], A_[k].rows(), A_[k].cols()) = A_[k];
    }
    return true;
  }
  const std::vector<MatrixXd>& A() const { return A_; }

 private:
  std::vector<MatrixXd> A_;
  VectorXd c_;
};

inline MatrixXd randomMatrix(std::mt19937& rng, int rows, int cols) {
  std::normal_distribution<double> n(0.0, 1.0);
  return MatrixXd::NullaryExpr(rows, cols, [&] { return n(rng); });
}
inline VectorXd randomVec(std::mt19937& rng, int n) { return randomMatrix(rng, n, 1); }

inline MatrixXd informationOf(const MarginalResult& m) { return m.sqrt_information.transpose() * m.sqrt_information; }
inline VectorXd gradientOf(const MarginalResult& m) { return m.sqrt_information.transpose() * m.offset; }
inline double relativeError(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
}

// Errors in the units of an information matrix B, so that entries of very different magnitude (bias random walk
// ~1e10, position ~1e2) are all compared: max |A_ij - B_ij| / sqrt(B_ii B_jj), and for gradients
// max |a_i - b_i| / sqrt(B_ii) over max |b_i| / sqrt(B_ii).
inline double scaledError(const MatrixXd& A, const MatrixXd& B) {
  const VectorXd d = B.diagonal().cwiseSqrt().cwiseInverse();
  return (d.asDiagonal() * (A - B) * d.asDiagonal()).cwiseAbs().maxCoeff();
}
inline double scaledGradientError(const VectorXd& a, const VectorXd& b, const MatrixXd& B) {
  const VectorXd d = B.diagonal().cwiseSqrt().cwiseInverse();
  return (d.asDiagonal() * (a - b)).cwiseAbs().maxCoeff() / std::max((d.asDiagonal() * b).cwiseAbs().maxCoeff(), 1e-300);
}

// A linear problem over Euclidean blocks with its independently stacked Jacobian J and residual r at the blocks'
// current values; columns in declaration order.
struct LinearProblem {
  std::vector<std::vector<double>> x;
  std::vector<int> col;
  std::vector<std::unique_ptr<LinearCost>> costs;
  std::vector<std::vector<int>> cost_blocks;
  int addBlock(const VectorXd& value) {
    col.push_back(x.empty() ? 0 : col.back() + static_cast<int>(x.back().size()));
    x.emplace_back(value.data(), value.data() + value.size());
    return static_cast<int>(x.size()) - 1;
  }
  void addCost(std::mt19937& rng, int rows, std::vector<int> blocks) {
    std::vector<MatrixXd> A;
    for (int b : blocks) A.push_back(randomMatrix(rng, rows, static_cast<int>(x[b].size())));
    costs.push_back(std::make_unique<LinearCost>(std::move(A), randomVec(rng, rows)));
    cost_blocks.push_back(std::move(blocks));
  }
  int dim() const { return col.back() + static_cast<int>(x.back().size()); }
  void stacked(MatrixXd& J, VectorXd& r) const {
    int rows = 0;
    for (const auto& c : costs) rows += c->num_residuals();
    J = MatrixXd::Zero(rows, dim());
    r.resize(rows);
    int row = 0;
    for (std::size_t i = 0; i < costs.size(); ++i) {
      std::vector<const double*> p;
      for (int b : cost_blocks[i]) p.push_back(x[b].data());
      costs[i]->Evaluate(p.data(), r.data() + row, nullptr);
      for (std::size_t k = 0; k < p.size(); ++k) {
        const MatrixXd& A = costs[i]->A()[k];
        J.block(row, col[cost_blocks[i][k]], A.rows(), A.cols()) = A;
      }
      row += costs[i]->num_residuals();
    }
  }
  SchurMarginalizer marginalizer() {
    SchurMarginalizer m;
    for (auto& b : x) m.addBlock(b.data(), static_cast<int>(b.size()), nullptr);
    for (std::size_t i = 0; i < costs.size(); ++i) {
      std::vector<double*> p;
      for (int b : cost_blocks[i]) p.push_back(x[b].data());
      m.addResidual(costs[i].get(), nullptr, p);
    }
    return m;
  }
};

// Closed-form Gaussian marginal (no Schur formula): with H = J^T J, g = J^T r, the kept blocks' marginal
// information is ((H^-1)_kk)^-1 and the kept part of the full minimiser dx* = -H^-1 g is the prior's minimiser.
inline void expectExactMarginal(const LinearProblem& p, const std::vector<int>& kept, const MarginalResult& m, double tol) {
  MatrixXd J;
  VectorXd r;
  p.stacked(J, r);
  const MatrixXd H = J.transpose() * J;
  const MatrixXd cov = H.inverse();
  const VectorXd dx = -cov * (J.transpose() * r);
  std::vector<int> idx;
  for (int b : kept) {
    for (std::size_t i = 0; i < p.x[b].size(); ++i) idx.push_back(p.col[b] + static_cast<int>(i));
  }
  const int n = static_cast<int>(idx.size());
  MatrixXd cov_kk(n, n);
  VectorXd dx_k(n);
  for (int i = 0; i < n; ++i) {
    dx_k(i) = dx(idx[i]);
    for (int j = 0; j < n; ++j) cov_kk(i, j) = cov(idx[i], idx[j]);
  }
  ASSERT_TRUE(m.ok) << m.reason;
  ASSERT_EQ(m.sqrt_information.cols(), n);
  EXPECT_EQ(m.rank, n);
  const MatrixXd A = informationOf(m);
  EXPECT_LT(relativeError(A, cov_kk.inverse()), tol);
  EXPECT_LT(relativeError(-A.ldlt().solve(gradientOf(m)), dx_k), tol);
}

// Two navigation states and the factors of test_marginalization's chain: a state prior and a pose prior on x0, the
// IMU and bias factors to x1.
struct ImuChain {
  std::array<double, 3> p0{}, v0{}, p1{}, v1{};
  std::array<double, 4> q0{0, 0, 0, 1}, q1{0, 0, 0, 1};
  std::array<double, 6> b0{}, b1{};
  imu::Preintegrator pim{imu::ImuBias{}, imu::PreintegrationConfig{}};
  std::vector<std::unique_ptr<ceres::CostFunction>> costs;
  std::vector<MarginalizationTerm> terms;
  RightQuaternionManifold manifold;

  std::array<double*, 4> x0() { return {p0.data(), q0.data(), v0.data(), b0.data()}; }
  std::array<double*, 4> x1() { return {p1.data(), q1.data(), v1.data(), b1.data()}; }
  explicit ImuChain(std::mt19937& rng) {
    for (int k = 0; k < 40; ++k) pim.integrate({0.1, -0.2, 0.3}, {0.5, 0.2, 9.9}, 0.005);
    const imu::NavState pred = pim.predict(imu::NavState{}, imu::ImuBias{});
    // Away from the optimum, so that the gradient b is not zero.
    Eigen::Map<Eigen::Vector3d>(p0.data()) = randomVector(rng, 2e-3);
    Eigen::Map<Eigen::Quaterniond>(q0.data()) = geometry::expQuat(randomVector(rng, 1e-3));
    Eigen::Map<Eigen::Vector3d>(p1.data()) = pred.T_world_imu.translation() + randomVector(rng, 2e-3);
    Eigen::Map<Eigen::Quaterniond>(q1.data()) =
        Eigen::Quaterniond(pred.T_world_imu.linear()) * geometry::expQuat(randomVector(rng, 1e-3));
    Eigen::Map<Eigen::Vector3d>(v1.data()) = pred.v_world + randomVector(rng, 2e-3);
    Eigen::Map<Vector6d>(b1.data()) << randomVector(rng, 1e-5), randomVector(rng, 1e-4);
    add(new NavStatePriorFactor(StatePoint{}, Vector15d::Constant(10.0).asDiagonal()), {0, 1, 2, 3});
    add(new PosePriorFactor(Eigen::Isometry3d::Identity(), poseSqrtInformation(0.05, 0.01)), {0, 1});
    add(new ImuPreintegrationFactor(pim), {0, 1, 2, 3, 4, 5, 6});
    add(new BiasRandomWalkFactor(2e-5, 3e-4, pim.deltaTime()), {3, 7});
  }
  void add(ceres::CostFunction* c, std::vector<int> blocks) {
    costs.emplace_back(c);
    terms.push_back({c, std::move(blocks)});
  }
  std::array<double*, 8> all() {
    const auto a = x0(), b = x1();
    return {a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]};
  }
  // losses[i] goes with terms[i] (nullptr = none).
  SchurMarginalizer marginalizer(const std::vector<const ceres::LossFunction*>& losses = {}, double eps = 1e-8) {
    SchurMarginalizer m(eps);
    const auto blocks = all();
    for (int b = 0; b < 8; ++b) {
      const int size = std::array<int, 4>{3, 4, 3, 6}[b % 4];
      m.addBlock(blocks[b], size, b % 4 == 1 ? &manifold : nullptr);
    }
    for (std::size_t i = 0; i < terms.size(); ++i) {
      std::vector<double*> ptrs;
      for (int b : terms[i].blocks) ptrs.push_back(blocks[b]);
      m.addResidual(terms[i].cost, i < losses.size() ? losses[i] : nullptr, ptrs);
    }
    return m;
  }
};

}  // namespace drover::backend::test
