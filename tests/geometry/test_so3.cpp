#include <gtest/gtest.h>

#include <random>

#include "geometry/so3.hpp"

using namespace drover::geometry;

namespace {
Eigen::Vector3d randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return scale * Eigen::Vector3d(u(rng), u(rng), u(rng));
}

// Central difference of f at x: column i = (f(x + h e_i) - f(x - h e_i)) / 2h, with f returning a tangent vector.
template <typename F>
Eigen::Matrix3d numericalJacobian(F f, const Eigen::Vector3d& x, double h = 1e-6) {
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[i] = h;
    J.col(i) = (f(x + e) - f(x - e)) / (2 * h);
  }
  return J;
}
TEST(SO3, YawOfIsTheHeadingOfTheXAxisWhateverTheTilt) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(-0.05, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  EXPECT_NEAR(yawOf(R), 0.7, 1e-12);
  EXPECT_NEAR(yawOf(Eigen::AngleAxisd(-3.0, Eigen::Vector3d::UnitZ()).toRotationMatrix()), -3.0, 1e-12);
}

TEST(SO3, WithRollPitchOfKeepsOneHeadingAndTheOthersTilt) {
  const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(-1.2, Eigen::Vector3d::UnitZ()) *
                                Eigen::AngleAxisd(0.08, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(0.03, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix();
  const Eigen::Matrix3d heading = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d R = withRollPitchOf(heading, tilt);
  EXPECT_NEAR(yawOf(R), 0.4, 1e-12);
  // The same tilt: the world z axis seen from the body is unchanged.
  EXPECT_LT((R.transpose() * Eigen::Vector3d::UnitZ() - tilt.transpose() * Eigen::Vector3d::UnitZ()).norm(), 1e-12);
}

}  // namespace

TEST(SO3, HatIsTheCrossProductAndVeeInvertsIt) {
  const Eigen::Vector3d v(1, -2, 3), w(0.5, 4, -1);
  EXPECT_TRUE(hat(v) * w == v.cross(w));
  EXPECT_TRUE(vee(hat(v)) == v);
}

TEST(SO3, ExpOfAQuarterTurnAboutZRotatesXOntoY) {
  const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0, 0, M_PI / 2));
  EXPECT_TRUE((R * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(SO3, LogInvertsExpForAnglesFromZeroToNearlyPi) {
  std::mt19937 rng(1);
  for (double scale : {0.0, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 1.0, 3.0}) {
    for (int i = 0; i < 50; ++i) {
      Eigen::Vector3d phi = randomVector(rng, scale);
      if (phi.norm() > M_PI - 1e-6) phi *= (M_PI - 1e-6) / phi.norm();
      EXPECT_LT((logSO3(expSO3(phi)) - phi).norm(), 1e-10 * std::max(1.0, phi.norm())) << phi.transpose();
    }
  }
}

TEST(SO3, LogOfAHalfTurnHasAnglePi) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, -1).normalized();
  const Eigen::Vector3d phi = logSO3(expSO3(M_PI * axis));
  EXPECT_NEAR(phi.norm(), M_PI, 1e-9);
  EXPECT_NEAR(std::abs(phi.normalized().dot(axis)), 1.0, 1e-9);
}

TEST(SO3, RightJacobianMatchesNumericalDerivativeOfExp) {
  // Exp(phi + d) = Exp(phi) Exp(J_r d)  =>  J_r = d/dd Log(Exp(phi)^T Exp(phi + d)) at d = 0.
  std::mt19937 rng(2);
  for (double scale : {1e-7, 1e-3, 0.5, 2.0}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d phi = randomVector(rng, scale);
      const Eigen::Matrix3d R0t = expSO3(phi).transpose();
      auto f = [&](const Eigen::Vector3d& p) { return logSO3(R0t * expSO3(p)); };
      EXPECT_LT((rightJacobianSO3(phi) - numericalJacobian(f, phi)).norm(), 1e-7) << phi.transpose();
    }
  }
}

TEST(SO3, RightJacobianInverseIsTheInverseAndMatchesDerivativeOfLog) {
  std::mt19937 rng(3);
  for (double scale : {1e-7, 1e-3, 0.5, 2.0}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d phi = randomVector(rng, scale);
      EXPECT_LT((rightJacobianInverseSO3(phi) * rightJacobianSO3(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
      // Log(Exp(phi) Exp(d)) = phi + J_r^-1 d.
      const Eigen::Matrix3d R0 = expSO3(phi);
      auto f = [&](const Eigen::Vector3d& d) { return logSO3(R0 * expSO3(d)); };
      EXPECT_LT((rightJacobianInverseSO3(phi) - numericalJacobian(f, Eigen::Vector3d::Zero())).norm(), 1e-7);
    }
  }
}

TEST(SO3, LeftJacobianSatisfiesExpOfSumIsLeftPerturbation) {
  std::mt19937 rng(4);
  const Eigen::Vector3d phi = randomVector(rng, 1.0);
  const Eigen::Matrix3d R0t = expSO3(phi).transpose();
  auto f = [&](const Eigen::Vector3d& p) { return logSO3(expSO3(p) * R0t); };
  EXPECT_LT((leftJacobianSO3(phi) - numericalJacobian(f, phi)).norm(), 1e-7);
  EXPECT_LT((leftJacobianInverseSO3(phi) * leftJacobianSO3(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

TEST(SO3, SlerpHitsEndpointsAndMovesAtConstantAngularRate) {
  const Eigen::Quaterniond q0 = expQuat(Eigen::Vector3d(0.1, -0.2, 0.3));
  const Eigen::Quaterniond q1 = expQuat(Eigen::Vector3d(-0.5, 0.4, 1.2));
  EXPECT_TRUE(slerp(q0, q1, 0.0).isApprox(q0, 1e-12) || slerp(q0, q1, 0.0).coeffs().isApprox(-q0.coeffs(), 1e-12));
  EXPECT_NEAR(q1.angularDistance(slerp(q0, q1, 1.0)), 0.0, 1e-12);
  const double total = q0.angularDistance(q1);
  for (double a : {0.25, 0.5, 0.75}) {
    EXPECT_NEAR(q0.angularDistance(slerp(q0, q1, a)), a * total, 1e-12);
    EXPECT_NEAR(q1.angularDistance(slerp(q0, q1, a)), (1 - a) * total, 1e-12);
  }
}

TEST(SO3, OrthonormalizeReturnsTheNearestRotation) {
  const Eigen::Matrix3d R = expSO3(Eigen::Vector3d(0.3, 0.2, -0.1));
  Eigen::Matrix3d noisy = R;
  noisy(0, 1) += 1e-5;
  const Eigen::Matrix3d Rn = orthonormalize(noisy);
  EXPECT_LT((Rn * Rn.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(Rn.determinant(), 1.0, 1e-14);
  EXPECT_LT((Rn - R).norm(), 1e-5);
}
