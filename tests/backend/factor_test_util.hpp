#pragma once
// Numerical-Jacobian checks for the backend's Ceres factors: analytic Jacobians against central differences,
// both in the tangent space of RightQuaternionManifold (q -> q Exp(dtheta)) and in the ambient R^4.
#include <ceres/cost_function.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "backend/quaternion_manifold.hpp"
#include "geometry/so3.hpp"

namespace drover::backend::test {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// A parameter block's values; quaternions (Eigen x, y, z, w order) are perturbed through the manifold.
struct Param {
  std::vector<double> x;
  bool quaternion = false;
};

inline Eigen::VectorXd evaluate(const ceres::CostFunction& cost, const std::vector<Param>& params,
                                std::vector<RowMatrix>* jacobians = nullptr) {
  std::vector<const double*> ptrs;
  for (const auto& p : params) ptrs.push_back(p.x.data());
  Eigen::VectorXd r(cost.num_residuals());
  std::vector<double*> jac_ptrs;
  if (jacobians) {
    jacobians->clear();
    for (const auto& p : params) jacobians->emplace_back(cost.num_residuals(), static_cast<int>(p.x.size()));
    for (auto& j : *jacobians) jac_ptrs.push_back(j.data());
  }
  EXPECT_TRUE(cost.Evaluate(ptrs.data(), r.data(), jacobians ? jac_ptrs.data() : nullptr));
  return r;
}

// Largest relative difference |J_a - J_n|_max / |J_n|_max over blocks, tangent (manifold) space.
inline double tangentJacobianError(const ceres::CostFunction& cost, const std::vector<Param>& params,
                                   double h = 1e-6) {
  std::vector<RowMatrix> analytic;
  evaluate(cost, params, &analytic);
  const RightQuaternionManifold manifold;
  double worst = 0;
  for (std::size_t b = 0; b < params.size(); ++b) {
    const Param& p = params[b];
    const int tangent = p.quaternion ? 3 : static_cast<int>(p.x.size());
    Eigen::MatrixXd J_a = analytic[b];
    if (p.quaternion) {
      Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
      manifold.PlusJacobian(p.x.data(), P.data());
      J_a = analytic[b] * P;
    }
    Eigen::MatrixXd J_n(cost.num_residuals(), tangent);
    for (int k = 0; k < tangent; ++k) {
      std::vector<Param> plus = params, minus = params;
      if (p.quaternion) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d(k) = h;
        manifold.Plus(p.x.data(), d.data(), plus[b].x.data());
        d(k) = -h;
        manifold.Plus(p.x.data(), d.data(), minus[b].x.data());
      } else {
        plus[b].x[k] += h;
        minus[b].x[k] -= h;
      }
      J_n.col(k) = (evaluate(cost, plus) - evaluate(cost, minus)) / (2 * h);
    }
    const double scale = std::max(J_n.cwiseAbs().maxCoeff(), 1e-12);
    worst = std::max(worst, (J_a - J_n).cwiseAbs().maxCoeff() / scale);
  }
  return worst;
}

// The same in the ambient coordinates (every block perturbed additively; the factors normalise q).
inline double ambientJacobianError(const ceres::CostFunction& cost, const std::vector<Param>& params,
                                   double h = 1e-6) {
  std::vector<RowMatrix> analytic;
  evaluate(cost, params, &analytic);
  double worst = 0;
  for (std::size_t b = 0; b < params.size(); ++b) {
    Eigen::MatrixXd J_n(cost.num_residuals(), params[b].x.size());
    for (std::size_t k = 0; k < params[b].x.size(); ++k) {
      std::vector<Param> plus = params, minus = params;
      plus[b].x[k] += h;
      minus[b].x[k] -= h;
      J_n.col(static_cast<int>(k)) = (evaluate(cost, plus) - evaluate(cost, minus)) / (2 * h);
    }
    const double scale = std::max(J_n.cwiseAbs().maxCoeff(), 1e-12);
    worst = std::max(worst, (Eigen::MatrixXd(analytic[b]) - J_n).cwiseAbs().maxCoeff() / scale);
  }
  return worst;
}

inline Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

inline Eigen::Quaterniond randomRotation(std::mt19937& rng) {
  return geometry::expQuat(randomVector(rng, 2.0)).normalized();
}

inline Param vectorParam(const Eigen::VectorXd& v) { return {std::vector<double>(v.data(), v.data() + v.size())}; }
inline Param quaternionParam(const Eigen::Quaterniond& q) {
  const Eigen::Quaterniond n = q.normalized();
  return {{n.x(), n.y(), n.z(), n.w()}, true};
}

}  // namespace drover::backend::test
