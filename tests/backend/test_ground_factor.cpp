// The ground height factor: a feature on the surface below the robot, at the IMU's known height above it, gives the
// window a metric depth. Known answers and the numerical Jacobian of every block.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "backend/ground_factor.hpp"
#include "factor_test_util.hpp"
#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

constexpr double kGroundJacobianTolerance = 1e-6;  // relative, as test_factors.cpp

// A forward-looking camera 0.1 m above and 0.2 m ahead of the IMU, z_cam = x_body, x_cam = -y_body, y_cam = -z_body.
Eigen::Isometry3d forwardCamera() {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return geometry::makeIsometry(Eigen::Quaterniond(R), Eigen::Vector3d(0.2, 0, 0.1));
}

std::vector<Param> paramsOf(const Eigen::Isometry3d& T_imu_cam, double inverse_depth) {
  return {vectorParam(T_imu_cam.translation()), quaternionParam(Eigen::Quaterniond(T_imu_cam.linear())),
          vectorParam(Eigen::Matrix<double, 1, 1>(inverse_depth))};
}

}  // namespace

TEST(GroundHeightFactor, IsZeroForAPointOnTheGroundAndGrowsWithTheHeightErrorInSigmas) {
  // The IMU 0.4 m above the ground, the camera 0.5 m: a ground point 3 m ahead of the camera lies 0.5 m below it,
  // seen at y_cam / z_cam = 0.5 / 3, depth 3 m along the camera's z.
  const Eigen::Isometry3d T_ic = forwardCamera();
  const GroundHeightFactor factor(Eigen::Vector2d(0.1, 0.5 / 3.0), 0.4, 0.02);
  EXPECT_NEAR(evaluate(factor, paramsOf(T_ic, 1.0 / 3.0))(0), 0.0, 1e-12);
  // Depth 10 % long: the point lies 0.05 m lower, 2.5 sigma below the ground.
  EXPECT_NEAR(evaluate(factor, paramsOf(T_ic, 1.0 / 3.3))(0), -2.5, 1e-9);
  // Depth 10 % short: 0.05 m above it.
  EXPECT_NEAR(evaluate(factor, paramsOf(T_ic, 1.0 / 2.7))(0), 2.5, 1e-9);
}

TEST(GroundHeightFactor, AnalyticJacobiansMatchNumericalOnesForEveryBlock) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d T_ic =
        forwardCamera() * geometry::makeIsometry(geometry::expQuat(0.2 * Eigen::Vector3d(u(rng), u(rng), u(rng))),
                                                 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const GroundHeightFactor factor(Eigen::Vector2d(0.4 * u(rng), 0.2 + 0.2 * u(rng)), 0.4 + 0.2 * u(rng), 0.03);
    EXPECT_LT(tangentJacobianError(factor, paramsOf(T_ic, 0.3 + 0.2 * u(rng))), kGroundJacobianTolerance) << trial;
  }
}

TEST(GroundHeightFactor, RejectsANonPositiveHeightOrSigmaAndAZeroInverseDepth) {
  EXPECT_THROW(GroundHeightFactor(Eigen::Vector2d(0, 0.2), 0.0, 0.02), std::invalid_argument);
  EXPECT_THROW(GroundHeightFactor(Eigen::Vector2d(0, 0.2), 0.4, 0.0), std::invalid_argument);
  EXPECT_THROW(GroundHeightFactor(Eigen::Vector2d(NAN, 0.2), 0.4, 0.02), std::invalid_argument);
  const GroundHeightFactor factor(Eigen::Vector2d(0, 0.2), 0.4, 0.02);
  std::vector<Param> params = paramsOf(forwardCamera(), 0.0);
  std::vector<const double*> blocks;
  for (const Param& p : params) blocks.push_back(p.x.data());
  double r = 0;
  EXPECT_FALSE(factor.Evaluate(blocks.data(), &r, nullptr));
}
