#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "backend/quaternion_manifold.hpp"
#include "backend/visual_factors.hpp"
#include "factor_test_util.hpp"
#include "geometry/se3.hpp"
#include "geometry/so3.hpp"

using namespace drover;
using namespace drover::backend;
using namespace drover::backend::test;

namespace {

constexpr double kVisualJacobianTolerance = 1e-6;  // relative, as test_factors.cpp
constexpr double kFocal = 460.0;             // [px]
constexpr double kSigmaPx = 1.5;             // [px]
constexpr double kSqrtInfo = kFocal / kSigmaPx;

// The values of ReprojectionFactor's eight parameter blocks.
struct Blocks {
  Eigen::Isometry3d T_world_imu_i, T_world_imu_j, T_imu_cam;
  double inverse_depth = 0;  // [1/m]
  double td = 0;             // [s]
};

std::vector<Param> paramsOf(const Blocks& b) {
  const auto pose = [](const Eigen::Isometry3d& T, std::vector<Param>& out) {
    out.push_back(vectorParam(T.translation()));
    out.push_back(quaternionParam(Eigen::Quaterniond(T.linear())));
  };
  std::vector<Param> out;
  pose(b.T_world_imu_i, out);
  pose(b.T_world_imu_j, out);
  pose(b.T_imu_cam, out);
  out.push_back(vectorParam(Eigen::Matrix<double, 1, 1>(b.inverse_depth)));
  out.push_back(vectorParam(Eigen::Matrix<double, 1, 1>(b.td)));
  return out;
}

bool evaluateRaw(const ReprojectionFactor& f, const std::vector<Param>& params, Eigen::Vector2d* r) {
  std::vector<const double*> ptrs;
  for (const auto& p : params) ptrs.push_back(p.x.data());
  return f.Evaluate(ptrs.data(), r->data(), nullptr);
}

Eigen::Vector2d project(const Eigen::Vector3d& P) { return P.head<2>() / P.z(); }

Eigen::Isometry3d randomPose(std::mt19937& rng, double rotation, double translation) {
  return geometry::makeIsometry(geometry::expQuat(randomVector(rng, rotation)), randomVector(rng, translation));
}

// A random well-conditioned configuration: a point 2-8 m in front of anchor camera i, camera j displaced by up to
// 0.5 m and 0.3 rad (so the point stays in front), a non-identity extrinsic, observations off their exact
// projections by a few pixels, non-zero velocities and td's. Returns the factor; fills the blocks.
ReprojectionFactor randomFactor(std::mt19937& rng, Blocks* b) {
  std::uniform_real_distribution<double> depth(2.0, 8.0);
  b->T_world_imu_i = randomPose(rng, 2.0, 5.0);
  b->T_imu_cam = randomPose(rng, 2.0, 0.2);
  const Eigen::Isometry3d T_ci_cj = randomPose(rng, 0.3, 0.5);
  const Eigen::Isometry3d T_w_ci = b->T_world_imu_i * b->T_imu_cam;
  b->T_world_imu_j = T_w_ci * T_ci_cj * geometry::inverse(b->T_imu_cam);
  const Eigen::Vector2d xy = randomVector(rng, 0.4).head<2>();
  const double z = depth(rng);
  const Eigen::Vector3d P_ci(xy.x() * z, xy.y() * z, z);
  const Eigen::Vector2d noise_i = randomVector(rng, 3.0 / kFocal).head<2>(),
                        noise_j = randomVector(rng, 3.0 / kFocal).head<2>();
  const Eigen::Vector2d vel_i = randomVector(rng, 0.3).head<2>(), vel_j = randomVector(rng, 0.3).head<2>();
  const double td_i = randomVector(rng, 0.02).x(), td_j = randomVector(rng, 0.02).x();
  b->inverse_depth = (1.0 / z) * (1.0 + randomVector(rng, 0.2).x());
  b->td = randomVector(rng, 0.02).x();
  return ReprojectionFactor(xy + noise_i, project(geometry::inverse(T_ci_cj) * P_ci) + noise_j, vel_i, vel_j, td_i,
                            td_j, kSqrtInfo);
}

// A frame whose camera moves laterally (in its own x-y plane) at constant velocity u [m/s] around the state time,
// so a static point's normalised image coordinates move exactly linearly in time, at -u.xy / Z.
struct MovingFrame {
  Eigen::Isometry3d T_world_cam;  // at the state time
  Eigen::Vector3d u_cam;          // [m/s] camera velocity in its own frame, z = 0
  double td_state = 0;            // [s] the td the state time was computed with
};

struct Observation {
  Eigen::Vector2d obs, velocity;
};

// What the camera sees at capture (IMU) time t_cam + td_true, the state being at t_cam + td_state.
Observation observe(const MovingFrame& f, const Eigen::Vector3d& P_world, double td_true) {
  const Eigen::Vector3d P_cam = geometry::inverse(f.T_world_cam) * P_world;
  const double tau = td_true - f.td_state;  // capture time - state time [s]
  return {project(P_cam - tau * f.u_cam), -f.u_cam.head<2>() / P_cam.z()};
}

ReprojectionFactor movingFactor(const MovingFrame& fi, const MovingFrame& fj, const Eigen::Vector3d& P_world,
                                double td_true) {
  const Observation oi = observe(fi, P_world, td_true), oj = observe(fj, P_world, td_true);
  return ReprojectionFactor(oi.obs, oj.obs, oi.velocity, oj.velocity, fi.td_state, fj.td_state, kSqrtInfo);
}

}  // namespace

TEST(ReprojectionFactor, IsZeroAtTheExactProjectionAndOneOverSigmaForAOnePixelShift) {
  std::mt19937 rng(11);
  Blocks b;
  b.T_world_imu_i = randomPose(rng, 2.0, 5.0);
  b.T_imu_cam = randomPose(rng, 2.0, 0.2);
  const Eigen::Isometry3d T_ci_cj = randomPose(rng, 0.2, 0.5);
  b.T_world_imu_j = b.T_world_imu_i * b.T_imu_cam * T_ci_cj * geometry::inverse(b.T_imu_cam);
  const Eigen::Vector3d P_ci(0.7, -0.4, 4.0);
  b.inverse_depth = 1.0 / P_ci.z();
  b.td = 0.013;
  const Eigen::Vector2d obs_j = project(geometry::inverse(T_ci_cj) * P_ci);
  // Zero velocities: the td shift is then irrelevant, whatever td is.
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  const ReprojectionFactor exact(project(P_ci), obs_j, zero, zero, 0.0, 0.0, kSqrtInfo);
  EXPECT_LT(evaluate(exact, paramsOf(b)).norm(), 1e-9);
  // Observed 1 px to the right (1 / f on the normalised plane): residual -1 / sigma in x, 0 in y.
  const ReprojectionFactor shifted(project(P_ci), obs_j + Eigen::Vector2d(1.0 / kFocal, 0), zero, zero, 0.0, 0.0,
                                   kSqrtInfo);
  const Eigen::VectorXd r = evaluate(shifted, paramsOf(b));
  EXPECT_NEAR(r(0), -1.0 / kSigmaPx, 1e-9);
  EXPECT_NEAR(r(1), 0.0, 1e-9);
  // The depth seen from camera j is the point's z in that camera.
  std::vector<const double*> ptrs;
  const auto params = paramsOf(b);
  for (const auto& p : params) ptrs.push_back(p.x.data());
  EXPECT_NEAR(exact.cheirality(ptrs.data()), (geometry::inverse(T_ci_cj) * P_ci).z(), 1e-12);
}

TEST(ReprojectionFactor, AnalyticJacobiansMatchCentralDifferencesWithTimeOffsetAndExtrinsic) {
  for (unsigned seed : {21u, 22u, 23u, 24u, 25u, 26u}) {
    std::mt19937 rng(seed);
    Blocks b;
    const ReprojectionFactor factor = randomFactor(rng, &b);
    const auto params = paramsOf(b);
    EXPECT_GT(evaluate(factor, params).norm(), 0.5) << "seed " << seed;  // away from the minimum
    EXPECT_LT(tangentJacobianError(factor, params), kVisualJacobianTolerance) << "seed " << seed;
    EXPECT_LT(ambientJacobianError(factor, params), kVisualJacobianTolerance) << "seed " << seed;
  }
}

TEST(ReprojectionFactor, SkipsNullJacobianBlocksAndFillsTheOthersAsAFullEvaluation) {
  std::mt19937 rng(31);
  Blocks b;
  const ReprojectionFactor factor = randomFactor(rng, &b);
  const auto params = paramsOf(b);
  std::vector<RowMatrix> full;
  const Eigen::VectorXd r_full = evaluate(factor, params, &full);
  std::vector<const double*> ptrs;
  for (const auto& p : params) ptrs.push_back(p.x.data());
  for (std::size_t requested = 0; requested < params.size(); ++requested) {
    RowMatrix J = RowMatrix::Constant(2, static_cast<int>(params[requested].x.size()), 1e300);
    std::vector<double*> jac(params.size(), nullptr);
    jac[requested] = J.data();
    Eigen::Vector2d r;
    ASSERT_TRUE(factor.Evaluate(ptrs.data(), r.data(), jac.data()));
    EXPECT_EQ(r, Eigen::Vector2d(r_full));
    EXPECT_EQ(J, full[requested]) << "block " << requested;
  }
}

TEST(ReprojectionFactor, TimeOffsetMovesObservationsAlongTheirVelocityZeroResidualOnlyAtTheTrueTd) {
  // Frames i and j move differently (otherwise a common time shift equals a shift of the point and td would be
  // invisible); their state times were computed with different td estimates.
  const Eigen::Isometry3d T_imu_cam = geometry::makeIsometry(
      geometry::expQuat(Eigen::Vector3d(-1.2, 0.1, -1.5)), Eigen::Vector3d(0.05, -0.02, 0.1));
  const MovingFrame fi{geometry::makeIsometry(geometry::expQuat(Eigen::Vector3d(0.1, 0.2, 0.0)),
                                              Eigen::Vector3d(0, 0, 0)),
                       {1.0, 0.3, 0.0}, 0.002};
  const MovingFrame fj{geometry::makeIsometry(geometry::expQuat(Eigen::Vector3d(0.0, 0.3, 0.1)),
                                              Eigen::Vector3d(0.4, 0.1, 0.05)),
                       {-0.8, 0.5, 0.0}, 0.004};
  const Eigen::Vector3d P_world(0.8, -0.5, 5.0);
  const double td_true = 0.02;  // [s]
  const ReprojectionFactor factor = movingFactor(fi, fj, P_world, td_true);
  Blocks b;
  b.T_imu_cam = T_imu_cam;
  b.T_world_imu_i = fi.T_world_cam * geometry::inverse(T_imu_cam);
  b.T_world_imu_j = fj.T_world_cam * geometry::inverse(T_imu_cam);
  b.inverse_depth = 1.0 / (geometry::inverse(fi.T_world_cam) * P_world).z();
  b.td = td_true;
  EXPECT_LT(evaluate(factor, paramsOf(b)).norm(), 1e-9);
  b.td = 0.0;  // 20 ms at ~0.2 1/s image velocity: about 2 px, more than one sigma
  EXPECT_GT(evaluate(factor, paramsOf(b)).norm(), 1.0);
  EXPECT_LT(tangentJacobianError(factor, paramsOf(b)), kVisualJacobianTolerance);
}

TEST(ReprojectionFactor, APointBehindACameraEvaluatesToALargeResidualAndOnlyASingularOneFails) {
  std::mt19937 rng(41);
  Blocks b;
  b.T_world_imu_i = randomPose(rng, 2.0, 5.0);
  b.T_imu_cam = randomPose(rng, 2.0, 0.2);
  // Camera j turned half a revolution about its y axis, 1 m behind camera i: the point 4 m ahead of i is 5 m
  // behind j.
  const Eigen::Isometry3d T_ci_cj = geometry::makeIsometry(geometry::expQuat(Eigen::Vector3d(0, M_PI, 0)),
                                                           Eigen::Vector3d(0, 0, -1.0));
  b.T_world_imu_j = b.T_world_imu_i * b.T_imu_cam * T_ci_cj * geometry::inverse(b.T_imu_cam);
  b.inverse_depth = 0.25;
  const Eigen::Vector2d zero = Eigen::Vector2d::Zero();
  const ReprojectionFactor factor(zero, zero, zero, zero, 0.0, 0.0, kSqrtInfo);
  auto params = paramsOf(b);
  std::vector<const double*> ptrs;
  for (const auto& p : params) ptrs.push_back(p.x.data());
  EXPECT_NEAR(factor.cheirality(ptrs.data()), -5.0, 1e-9);
  Eigen::Vector2d r;
  EXPECT_TRUE(evaluateRaw(factor, params, &r));  // finite: the robust loss bounds it, the step is not refused
  EXPECT_TRUE(r.allFinite());
  // The same cameras facing the same way: in front, evaluates.
  b.T_world_imu_j = b.T_world_imu_i * b.T_imu_cam * geometry::makeIsometry(Eigen::Matrix3d::Identity(),
                                                                           Eigen::Vector3d(0.3, 0, 0)) *
                    geometry::inverse(b.T_imu_cam);
  params = paramsOf(b);
  EXPECT_TRUE(evaluateRaw(factor, params, &r));
  // Negative inverse depth: behind anchor camera i, a large finite residual; zero: singular.
  params[6].x[0] = -0.25;
  EXPECT_TRUE(evaluateRaw(factor, params, &r));
  EXPECT_TRUE(r.allFinite());
  params[6].x[0] = 0.0;
  EXPECT_FALSE(evaluateRaw(factor, params, &r));
  params[6].x[0] = 0.25;
  params[7].x[0] = std::nan("");
  EXPECT_FALSE(evaluateRaw(factor, params, &r));
}

TEST(ReprojectionFactor, ConstructorRejectsNonFiniteInputAndNonPositiveInformation) {
  const Eigen::Vector2d ok(0.1, -0.2), bad(std::nan(""), 0.0), inf(0.0, INFINITY);
  EXPECT_NO_THROW(ReprojectionFactor(ok, ok, ok, ok, 0.01, -0.01, 300.0));
  EXPECT_THROW(ReprojectionFactor(bad, ok, ok, ok, 0, 0, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, inf, ok, ok, 0, 0, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, bad, ok, 0, 0, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, inf, 0, 0, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, ok, NAN, 0, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, ok, 0, INFINITY, 300.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, ok, 0, 0, 0.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, ok, 0, 0, -1.0), std::invalid_argument);
  EXPECT_THROW(ReprojectionFactor(ok, ok, ok, ok, 0, 0, NAN), std::invalid_argument);
}

TEST(InverseDepthFactor, WhitensTheInverseDepthErrorByTheFirstOrderSigmaOfOneOverD) {
  const double d = 4.0, sigma = 0.08;  // sigma(1/d) = 0.08 / 16 = 0.005 1/m
  const InverseDepthFactor factor(d, sigma);
  const auto residualAt = [&](double lambda) {
    return evaluate(factor, {vectorParam(Eigen::Matrix<double, 1, 1>(lambda))})(0);
  };
  EXPECT_NEAR(residualAt(0.25), 0.0, 1e-12);
  EXPECT_NEAR(residualAt(0.25 + 2 * 0.005), 2.0, 1e-9);
  // A depth one sigma farther: -1 to first order in sigma / d = 2 % (exactly -d / (d + sigma)).
  EXPECT_NEAR(residualAt(1.0 / (d + sigma)), -d / (d + sigma), 1e-9);
  EXPECT_NEAR(residualAt(1.0 / (d + sigma)), -1.0, 0.03);
  EXPECT_LT(tangentJacobianError(factor, {vectorParam(Eigen::Matrix<double, 1, 1>(0.3))}), kVisualJacobianTolerance);
}

TEST(InverseDepthFactor, RejectsNonPositiveOrNonFiniteDepthAndSigma) {
  EXPECT_THROW(InverseDepthFactor(0.0, 0.1), std::invalid_argument);
  EXPECT_THROW(InverseDepthFactor(-2.0, 0.1), std::invalid_argument);
  EXPECT_THROW(InverseDepthFactor(INFINITY, 0.1), std::invalid_argument);
  EXPECT_THROW(InverseDepthFactor(2.0, 0.0), std::invalid_argument);
  EXPECT_THROW(InverseDepthFactor(2.0, NAN), std::invalid_argument);
  EXPECT_NO_THROW(InverseDepthFactor(2.0, 0.1));
}

TEST(VisualFactors, CeresRecoversAPerturbedInverseDepthAndTheTimeOffsetFromSeveralFrames) {
  // Four frames with fixed poses and extrinsic, each camera moving in its own way around its state time; a feature
  // anchored in frame 0 seen by the other three (noise-free), plus a consistent lidar depth in the anchor camera.
  std::mt19937 rng(51);
  const Eigen::Isometry3d T_imu_cam = geometry::makeIsometry(
      geometry::expQuat(Eigen::Vector3d(-1.2, 0.1, -1.5)), Eigen::Vector3d(0.05, -0.02, 0.1));
  std::vector<MovingFrame> frames;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d u = randomVector(rng, 1.0);
    frames.push_back({geometry::makeIsometry(geometry::expQuat(randomVector(rng, 0.15)),
                                             Eigen::Vector3d(0.3 * k, 0.1 * k, 0.05 * k)),
                      {u.x(), u.y(), 0.0},
                      0.004});
  }
  const Eigen::Vector3d P_world(0.5, -0.3, 6.0);
  const double td_true = 0.015;  // [s]
  const double depth_true = (geometry::inverse(frames[0].T_world_cam) * P_world).z();

  std::vector<std::vector<double>> p(frames.size()), q(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Eigen::Isometry3d T_wi = frames[k].T_world_cam * geometry::inverse(T_imu_cam);
    p[k] = vectorParam(T_wi.translation()).x;
    q[k] = quaternionParam(Eigen::Quaterniond(T_wi.linear())).x;
  }
  std::vector<double> p_ic = vectorParam(T_imu_cam.translation()).x;
  std::vector<double> q_ic = quaternionParam(Eigen::Quaterniond(T_imu_cam.linear())).x;
  double lambda = 0.5;  // 2 m instead of ~6 m
  double td = 0.0;

  ceres::Problem problem;
  for (std::size_t k = 1; k < frames.size(); ++k) {
    problem.AddResidualBlock(new ReprojectionFactor(movingFactor(frames[0], frames[k], P_world, td_true)), nullptr,
                             p[0].data(), q[0].data(), p[k].data(), q[k].data(), p_ic.data(), q_ic.data(), &lambda,
                             &td);
  }
  problem.AddResidualBlock(new InverseDepthFactor(depth_true, 0.1), nullptr, &lambda);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    problem.SetManifold(q[k].data(), new RightQuaternionManifold);
    problem.SetParameterBlockConstant(p[k].data());
    problem.SetParameterBlockConstant(q[k].data());
  }
  problem.SetManifold(q_ic.data(), new RightQuaternionManifold);
  problem.SetParameterBlockConstant(p_ic.data());
  problem.SetParameterBlockConstant(q_ic.data());

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.function_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  options.gradient_tolerance = 1e-16;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();
  EXPECT_NEAR(lambda, 1.0 / depth_true, 1e-9) << summary.BriefReport();
  EXPECT_NEAR(td, td_true, 1e-9) << summary.BriefReport();
  EXPECT_LT(summary.final_cost, 1e-16);
}
