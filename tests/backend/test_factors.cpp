#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "backend/imu_factors.hpp"
#include "backend/pose_factors.hpp"
#include "backend/quaternion_manifold.hpp"
#include "backend/state_prior_factor.hpp"
#include "factor_test_util.hpp"
#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

constexpr double kJacobianTolerance = 1e-6;  // relative, as the issue asks

// 0.4 s of a turning, accelerating body at 200 Hz, integrated at a non-zero linearisation bias.
imu::Preintegrator makePreintegration(std::mt19937& rng) {
  imu::ImuBias bias_hat;
  bias_hat.gyro = {0.01, -0.02, 0.015};
  bias_hat.acc = {0.1, -0.05, 0.2};
  imu::Preintegrator pim(bias_hat, imu::PreintegrationConfig{});
  const Eigen::Vector3d w0 = randomVector(rng, 0.8), a0 = randomVector(rng, 2.0) + Eigen::Vector3d(0, 0, 9.81);
  for (int k = 0; k < 80; ++k) {
    const double t = k * 0.005;
    pim.integrate(w0 + Eigen::Vector3d(0.3 * std::sin(3 * t), 0.2 * std::cos(2 * t), 0.1 * t),
                  a0 + Eigen::Vector3d(std::sin(5 * t), 0.5 * std::cos(4 * t), -0.3 * t), 0.005);
  }
  return pim;
}

imu::NavState randomState(std::mt19937& rng) {
  imu::NavState s;
  s.T_world_imu = geometry::makeIsometry(randomRotation(rng), randomVector(rng, 5.0));
  s.v_world = randomVector(rng, 3.0);
  return s;
}

Eigen::VectorXd biasVector(const imu::ImuBias& b) {
  Vector6d v;
  v << b.gyro, b.acc;
  return v;
}

std::vector<Param> imuParams(const imu::NavState& i, const imu::ImuBias& b, const imu::NavState& j) {
  return {vectorParam(i.T_world_imu.translation()), quaternionParam(Eigen::Quaterniond(i.T_world_imu.linear())),
          vectorParam(i.v_world),                   vectorParam(biasVector(b)),
          vectorParam(j.T_world_imu.translation()), quaternionParam(Eigen::Quaterniond(j.T_world_imu.linear())),
          vectorParam(j.v_world)};
}

// State j near the prediction but off it by a few cm, cm/s and degrees, so every residual is non-trivial.
imu::NavState perturbedPrediction(const imu::Preintegrator& pim, const imu::NavState& i, const imu::ImuBias& b,
                                  std::mt19937& rng) {
  imu::NavState j = pim.predict(i, b);
  j.T_world_imu = j.T_world_imu * geometry::expSE3((Vector6d() << randomVector(rng, 0.05),
                                                    randomVector(rng, 0.05)).finished());
  j.v_world += randomVector(rng, 0.05);
  return j;
}

imu::ImuBias offsetBias(const imu::Preintegrator& pim, std::mt19937& rng) {
  imu::ImuBias b = pim.biasHat();
  b.gyro += randomVector(rng, 0.01);
  b.acc += randomVector(rng, 0.1);
  return b;
}

}  // namespace

TEST(RightQuaternionManifold, PlusIsRightMultiplicationAndMinusItsInverseWithConsistentJacobians) {
  std::mt19937 rng(1);
  const RightQuaternionManifold m;
  for (int trial = 0; trial < 10; ++trial) {
    const Eigen::Quaterniond q = randomRotation(rng);
    const Eigen::Vector3d d = randomVector(rng, 0.5);
    Eigen::Quaterniond out;
    m.Plus(q.coeffs().data(), d.data(), out.coeffs().data());
    EXPECT_LT((out.toRotationMatrix() - q.toRotationMatrix() * geometry::expSO3(d)).norm(), 1e-12);
    Eigen::Vector3d back;
    m.Minus(out.coeffs().data(), q.coeffs().data(), back.data());
    EXPECT_LT((back - d).norm(), 1e-12);
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P, P_num;
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> M;
    m.PlusJacobian(q.coeffs().data(), P.data());
    m.MinusJacobian(q.coeffs().data(), M.data());
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d e = Eigen::Vector3d::Zero();
      Eigen::Quaterniond qp, qm;
      e(k) = 1e-6;
      m.Plus(q.coeffs().data(), e.data(), qp.coeffs().data());
      e(k) = -1e-6;
      m.Plus(q.coeffs().data(), e.data(), qm.coeffs().data());
      P_num.col(k) = (qp.coeffs() - qm.coeffs()) / 2e-6;
    }
    EXPECT_LT((P - P_num).norm(), 1e-8);
    EXPECT_LT((M * P - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
}

TEST(ImuPreintegrationFactor, ResidualIsZeroAtThePredictedStateAndUnwhitensToPreintegratorResidual) {
  std::mt19937 rng(2);
  const imu::Preintegrator pim = makePreintegration(rng);
  const ImuPreintegrationFactor factor(pim);
  const imu::NavState i = randomState(rng);
  const imu::ImuBias b = offsetBias(pim, rng);
  const Eigen::VectorXd r0 = evaluate(factor, imuParams(i, b, pim.predict(i, b)));
  EXPECT_LT(r0.norm(), 1e-6) << r0.transpose();

  const imu::NavState j = perturbedPrediction(pim, i, b, rng);
  const Eigen::VectorXd r = evaluate(factor, imuParams(i, b, j));
  const imu::Vector9d expected = pim.residual(i, j, b);
  EXPECT_GT(expected.norm(), 1e-3);
  EXPECT_LT((factor.sqrtInformation().triangularView<Eigen::Upper>().solve(r) - expected).norm(),
            1e-9 * expected.norm());
  // Whitening: L^T L = covariance^-1.
  const imu::Matrix9d L = factor.sqrtInformation();
  EXPECT_LT((L.transpose() * L * pim.covariance() - imu::Matrix9d::Identity()).norm(), 1e-6);
}

TEST(ImuPreintegrationFactor, AnalyticJacobiansMatchCentralDifferencesIncludingBiasCorrection) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    const imu::Preintegrator pim = makePreintegration(rng);
    const ImuPreintegrationFactor factor(pim);
    const imu::NavState i = randomState(rng);
    const imu::ImuBias b = offsetBias(pim, rng);
    const auto params = imuParams(i, b, perturbedPrediction(pim, i, b, rng));
    EXPECT_LT(tangentJacobianError(factor, params), kJacobianTolerance) << "trial " << trial;
    EXPECT_LT(ambientJacobianError(factor, params), kJacobianTolerance) << "trial " << trial;
  }
}

TEST(ImuPreintegrationFactor, RejectsAnEmptyPreintegration) {
  const imu::Preintegrator empty(imu::ImuBias{}, imu::PreintegrationConfig{});
  EXPECT_THROW(ImuPreintegrationFactor{empty}, std::invalid_argument);
}

TEST(BiasRandomWalkFactor, WhitensTheBiasChangeBySigmaTimesSqrtDtWithExactJacobians) {
  const BiasRandomWalkFactor factor(2e-5, 3e-4, 0.25);
  Vector6d b_i, b_j;
  b_i << 0.01, -0.02, 0.03, 0.1, 0.2, -0.3;
  b_j = b_i;
  EXPECT_LT(evaluate(factor, {vectorParam(b_i), vectorParam(b_j)}).norm(), 1e-15);
  b_j(0) += 1e-5;  // one sigma sqrt(dt) = 2e-5 * 0.5
  b_j(4) -= 3e-4;  // two sigma sqrt(dt) = 2 * 3e-4 * 0.5
  const Eigen::VectorXd r = evaluate(factor, {vectorParam(b_i), vectorParam(b_j)});
  EXPECT_NEAR(r(0), 1.0, 1e-9);
  EXPECT_NEAR(r(4), -2.0, 1e-9);
  EXPECT_LT(tangentJacobianError(factor, {vectorParam(b_i), vectorParam(b_j)}), kJacobianTolerance);
  EXPECT_THROW(BiasRandomWalkFactor(0.0, 3e-4, 0.1), std::invalid_argument);
}

TEST(BiasPriorFactor, WhitensTheBiasErrorPerAxisWithExactJacobians) {
  Vector6d measured;
  measured << 0.002, -0.001, 0.0015, 0.02, -0.03, 0.01;
  const BiasPriorFactor factor(measured, 0.001, 0.02);
  EXPECT_LT(evaluate(factor, {vectorParam(measured)}).norm(), 1e-15);
  Vector6d b = measured;
  b(1) += 0.002;  // two gyro sigmas
  b(5) -= 0.01;   // half an accelerometer sigma
  const Eigen::VectorXd r = evaluate(factor, {vectorParam(b)});
  EXPECT_NEAR(r(1), 2.0, 1e-9);
  EXPECT_NEAR(r(5), -0.5, 1e-9);
  EXPECT_NEAR(r.norm(), std::sqrt(4.25), 1e-9);
  EXPECT_LT(tangentJacobianError(factor, {vectorParam(b)}), kJacobianTolerance);
  EXPECT_THROW(BiasPriorFactor(measured, 0.0, 0.02), std::invalid_argument);
  measured(3) = std::nan("");
  EXPECT_THROW(BiasPriorFactor(measured, 0.001, 0.02), std::invalid_argument);
}

TEST(PosePriorFactor, GivesTheWhitenedSe3ErrorAndExactJacobians) {
  std::mt19937 rng(4);
  const Eigen::Isometry3d T_m = randomState(rng).T_world_imu;
  const PosePriorFactor factor(T_m, poseSqrtInformation(0.05, 0.01));
  const auto paramsOf = [](const Eigen::Isometry3d& T) {
    return std::vector<Param>{vectorParam(T.translation()), quaternionParam(Eigen::Quaterniond(T.linear()))};
  };
  EXPECT_LT(evaluate(factor, paramsOf(T_m)).norm(), 1e-9);
  // 0.1 m along x and 0.02 rad about the body z axis: 2 and 2 sigma.
  Eigen::Isometry3d T = T_m;
  T.translation().x() += 0.1;
  T.linear() = T.linear() * geometry::expSO3(Eigen::Vector3d(0, 0, 0.02));
  const Eigen::VectorXd r = evaluate(factor, paramsOf(T));
  EXPECT_NEAR(r(0), 2.0, 1e-9);
  EXPECT_NEAR(r(5), 2.0, 1e-9);
  EXPECT_NEAR(r.norm(), std::sqrt(8.0), 1e-9);
  Matrix6d L = poseSqrtInformation(0.05, 0.01);
  L(0, 4) = 3.0;  // a full (correlated) sqrt information
  const PosePriorFactor correlated(T_m, L);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Isometry3d Tx = T_m * geometry::expSE3((Vector6d() << randomVector(rng, 1.0),
                                                         randomVector(rng, 1.0)).finished());
    EXPECT_LT(tangentJacobianError(correlated, paramsOf(Tx)), kJacobianTolerance);
    EXPECT_LT(ambientJacobianError(correlated, paramsOf(Tx)), kJacobianTolerance);
  }
}

TEST(RelativePoseFactor, IsZeroForTheTrueRelativePoseAndHasExactJacobians) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Isometry3d T_i = randomState(rng).T_world_imu, T_j = randomState(rng).T_world_imu;
    const Eigen::Isometry3d T_i_j = geometry::inverse(T_i) * T_j;
    const auto paramsOf = [](const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) {
      return std::vector<Param>{vectorParam(A.translation()), quaternionParam(Eigen::Quaterniond(A.linear())),
                                vectorParam(B.translation()), quaternionParam(Eigen::Quaterniond(B.linear()))};
    };
    const RelativePoseFactor factor(T_i_j, poseSqrtInformation(0.1, 0.02));
    EXPECT_LT(evaluate(factor, paramsOf(T_i, T_j)).norm(), 1e-9);
    const Eigen::Isometry3d T_j_off = T_j * geometry::expSE3((Vector6d() << randomVector(rng, 0.5),
                                                              randomVector(rng, 0.5)).finished());
    EXPECT_GT(evaluate(factor, paramsOf(T_i, T_j_off)).norm(), 1.0);
    EXPECT_LT(tangentJacobianError(factor, paramsOf(T_i, T_j_off)), kJacobianTolerance);
    EXPECT_LT(ambientJacobianError(factor, paramsOf(T_i, T_j_off)), kJacobianTolerance);
  }
}

TEST(NavStatePriorFactor, IsTheOffsetAtTheLinearisationPointAndHasExactJacobians) {
  std::mt19937 rng(6);
  StatePoint lin;
  lin.p_world = randomVector(rng, 3.0);
  lin.q_world_imu = randomRotation(rng);
  lin.v_world = randomVector(rng, 2.0);
  lin.bias << randomVector(rng, 0.01), randomVector(rng, 0.1);
  Matrix15d L = Matrix15d::Random();
  const Vector15d offset = Vector15d::Random();
  const NavStatePriorFactor factor(lin, L, offset);
  const auto paramsOf = [](const StatePoint& s) {
    return std::vector<Param>{vectorParam(s.p_world), quaternionParam(s.q_world_imu), vectorParam(s.v_world),
                              vectorParam(s.bias)};
  };
  EXPECT_LT((evaluate(factor, paramsOf(lin)) - offset).norm(), 1e-12);
  StatePoint x = lin;
  x.p_world += randomVector(rng, 0.3);
  x.q_world_imu = lin.q_world_imu * geometry::expQuat(randomVector(rng, 0.4));
  x.v_world += randomVector(rng, 0.3);
  x.bias += Vector6d::Random() * 0.01;
  EXPECT_LT(tangentJacobianError(factor, paramsOf(x)), kJacobianTolerance);
  EXPECT_LT(ambientJacobianError(factor, paramsOf(x)), kJacobianTolerance);
}
