#include <gtest/gtest.h>

#include <random>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

using namespace drover::geometry;

namespace {
Vector6d randomTwist(std::mt19937& rng, double rot_scale, double trans_scale) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector6d xi;
  for (int i = 0; i < 3; ++i) xi[i] = trans_scale * u(rng);
  for (int i = 3; i < 6; ++i) xi[i] = rot_scale * u(rng);
  return xi;
}

template <typename F>
Matrix6d numericalJacobianSe3(F f, const Vector6d& x, double h = 1e-6) {
  Matrix6d J;
  for (int i = 0; i < 6; ++i) {
    Vector6d e = Vector6d::Zero();
    e[i] = h;
    J.col(i) = (f(x + e) - f(x - e)) / (2 * h);
  }
  return J;
}
}  // namespace

TEST(SE3, ExpOfPureTranslationTranslates) {
  Vector6d xi = Vector6d::Zero();
  xi.head<3>() << 1, 2, 3;
  const Eigen::Isometry3d T = expSE3(xi);
  EXPECT_TRUE(T.linear().isIdentity(1e-15));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
}

TEST(SE3, ExpOfAScrewMotionMatchesItsClosedForm) {
  // Rotating by pi/2 about z while moving along a circle of radius r: xi = [v; w] with v = (r w, 0, 0) ... the
  // endpoint of constant body twist (v = (1,0,0) m, w = (0,0,pi/2) rad) over unit time is (2/pi, 2/pi, 0).
  Vector6d xi;
  xi << 1, 0, 0, 0, 0, M_PI / 2;
  const Eigen::Isometry3d T = expSE3(xi);
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(2 / M_PI, 2 / M_PI, 0), 1e-12));
}

TEST(SE3, LogInvertsExp) {
  std::mt19937 rng(5);
  for (double rs : {0.0, 1e-9, 1e-4, 1e-2, 0.5, 2.5}) {
    for (int i = 0; i < 30; ++i) {
      Vector6d xi = randomTwist(rng, rs, 3.0);
      // Log returns angles in [0, pi]; keep the test inside the principal branch.
      if (xi.tail<3>().norm() > M_PI - 1e-3) xi.tail<3>() *= (M_PI - 1e-3) / xi.tail<3>().norm();
      EXPECT_LT((logSE3(expSE3(xi)) - xi).norm(), 1e-9) << xi.transpose();
    }
  }
}

TEST(SE3, InverseComposesToIdentity) {
  std::mt19937 rng(6);
  const Eigen::Isometry3d T = expSE3(randomTwist(rng, 1.0, 5.0));
  EXPECT_TRUE((T * inverse(T)).matrix().isIdentity(1e-12));
  EXPECT_TRUE(inverse(T).matrix().isApprox(T.inverse().matrix(), 1e-12));
}

TEST(SE3, AdjointMovesATwistAcrossFrames) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d T = expSE3(randomTwist(rng, 1.0, 2.0));
  const Vector6d xi = randomTwist(rng, 0.3, 0.5);
  const Eigen::Isometry3d lhs = T * expSE3(xi) * inverse(T);
  EXPECT_TRUE(lhs.matrix().isApprox(expSE3(adjointSE3(T) * xi).matrix(), 1e-10));
}

TEST(SE3, RightJacobianMatchesNumericalDerivativeOfExp) {
  // Exp(xi + d) = Exp(xi) Exp(J_r d)  =>  J_r = d/dd Log(Exp(xi)^-1 Exp(xi + d)).
  std::mt19937 rng(8);
  for (double rs : {1e-6, 5e-4, 1e-2, 0.7, 2.0}) {
    for (int i = 0; i < 10; ++i) {
      const Vector6d xi = randomTwist(rng, rs, 2.0);
      const Eigen::Isometry3d T0inv = inverse(expSE3(xi));
      auto f = [&](const Vector6d& x) { return logSE3(T0inv * expSE3(x)); };
      EXPECT_LT((rightJacobianSE3(xi) - numericalJacobianSe3(f, xi)).norm(), 1e-6) << xi.transpose();
    }
  }
}

TEST(SE3, RightJacobianInverseIsTheInverse) {
  std::mt19937 rng(9);
  for (double rs : {1e-6, 5e-4, 1e-2, 0.7, 2.0}) {
    const Vector6d xi = randomTwist(rng, rs, 2.0);
    EXPECT_LT((rightJacobianInverseSE3(xi) * rightJacobianSE3(xi) - Matrix6d::Identity()).norm(), 1e-9);
  }
}

TEST(SE3, InterpolationHitsEndpointsAndMidpoint) {
  const Eigen::Isometry3d T0 = makeIsometry(expSO3(Eigen::Vector3d(0, 0, 0.2)), Eigen::Vector3d(1, 0, 0));
  const Eigen::Isometry3d T1 = makeIsometry(expSO3(Eigen::Vector3d(0, 0, 0.8)), Eigen::Vector3d(3, 2, 0));
  EXPECT_TRUE(interpolate(T0, T1, 0.0).matrix().isApprox(T0.matrix(), 1e-12));
  EXPECT_TRUE(interpolate(T0, T1, 1.0).matrix().isApprox(T1.matrix(), 1e-12));
  const Eigen::Isometry3d mid = interpolate(T0, T1, 0.5);
  EXPECT_TRUE(mid.translation().isApprox(Eigen::Vector3d(2, 1, 0), 1e-12));
  EXPECT_NEAR(logSO3(mid.linear()).z(), 0.5, 1e-12);
  EXPECT_TRUE(interpolateGeodesic(T0, T1, 1.0).matrix().isApprox(T1.matrix(), 1e-10));
  EXPECT_NEAR(logSO3(interpolateGeodesic(T0, T1, 0.5).linear()).z(), 0.5, 1e-12);
}
