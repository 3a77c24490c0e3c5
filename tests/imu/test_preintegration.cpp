#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "geometry/so3.hpp"
#include "imu/imu_test_paths.hpp"
#include "imu/preintegration.hpp"
#include "sim/random.hpp"

using namespace drover;
using namespace drover::imu;
using namespace drover::imu::testing;

namespace {

PreintegrationConfig quietConfig() {
  PreintegrationConfig c;
  c.integration_sigma = 0;  // the simulator has no integration noise
  return c;
}

Preintegrator integrated(const std::vector<ImuSample>& imu, Time t0, Time t1, const ImuBias& bias_hat,
                         const PreintegrationConfig& config = PreintegrationConfig{}) {
  Preintegrator pre(bias_hat, config);
  pre.integrateRange(imu, t0, t1);
  return pre;
}

std::vector<ImuSample> withBias(std::vector<ImuSample> imu, const ImuBias& bias) {
  for (ImuSample& s : imu) {
    s.omega_imu += bias.gyro;
    s.acc_imu += bias.acc;
  }
  return imu;
}

double angleBetween(const Eigen::Matrix3d& A, const Eigen::Matrix3d& B) {
  return geometry::rotationAngle(A.transpose() * B);
}

struct OneSecondErrors {
  double position = 0, rotation = 0, velocity = 0;  // [m], [rad], [m/s] prediction minus truth
  Vector9d residual = Vector9d::Zero();             // at the true states
};

// Preintegrates [1.5, 2.5] s of the demanding path (vibrations at full amplitude) at `rate_hz` and predicts.
OneSecondErrors oneSecondErrors(double rate_hz) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(rate_hz), 1);
  const Time ti = 3 * kSec / 2, tj = ti + kSec;
  const Preintegrator pre = integrated(imu, ti, tj, ImuBias{});
  EXPECT_NEAR(pre.deltaTime(), 1.0, 1e-12);
  const NavState truth_i = navStateAt(path, ti), truth_j = navStateAt(path, tj);
  const NavState pred = pre.predict(truth_i, ImuBias{});
  EXPECT_EQ(pred.t, tj);
  OneSecondErrors e;
  e.position = (pred.T_world_imu.translation() - truth_j.T_world_imu.translation()).norm();
  e.rotation = angleBetween(pred.T_world_imu.linear(), truth_j.T_world_imu.linear());
  e.velocity = (pred.v_world - truth_j.v_world).norm();
  e.residual = pre.residual(truth_i, truth_j, ImuBias{});
  std::printf("[ figures ] 1 s at %g Hz: position %.3g m, rotation %.3g deg, velocity %.3g m/s\n", rate_hz,
              e.position, e.rotation / kDeg, e.velocity);
  return e;
}

}  // namespace

TEST(Preintegration, NoiseFreeImuOverOneSecondPredictsTheExactStateOnATurningClimbingJoltingPath) {
  // Zero-order hold (Forster Eq. 30 discretised) is first order in dt, and the 12 Hz, 5 mm vibration makes
  // ~28 m/s^2 of acceleration: at 200 Hz one second leaves ~1.3 cm and ~0.05 deg (printed below); 5 kHz brings it
  // under 1 mm, and halving dt halves the error, as a first-order scheme must.
  oneSecondErrors(200.0);
  const OneSecondErrors coarse = oneSecondErrors(2500.0), fine = oneSecondErrors(5000.0);
  EXPECT_LT(fine.position, 1e-3);
  EXPECT_LT(fine.rotation, 0.01 * kDeg);
  EXPECT_LT(fine.velocity, 1e-3);
  EXPECT_NEAR(coarse.position / fine.position, 2.0, 0.3);
  EXPECT_NEAR(coarse.velocity / fine.velocity, 2.0, 0.3);
  EXPECT_NEAR(coarse.rotation / fine.rotation, 2.0, 0.3);
  const Vector9d& r = fine.residual;
  std::printf("[ figures ] residual at the true states (5 kHz): phi %.3g rad, v %.3g m/s, p %.3g m\n",
              r.segment<3>(0).norm(), r.segment<3>(3).norm(), r.segment<3>(6).norm());
  EXPECT_LT(r.segment<3>(0).norm(), 0.01 * kDeg);
  EXPECT_LT(r.segment<3>(3).norm(), 1e-3);
  EXPECT_LT(r.segment<3>(6).norm(), 1e-3);
  // Sanity: the second really moves, turns and climbs.
  const sim::SplineTrajectory path = demandingPath();
  const NavState a = navStateAt(path, 3 * kSec / 2), b = navStateAt(path, 5 * kSec / 2);
  EXPECT_GT((b.T_world_imu.translation() - a.T_world_imu.translation()).norm(), 1.0);
  EXPECT_GT(angleBetween(a.T_world_imu.linear(), b.T_world_imu.linear()), 0.4);
  EXPECT_GT(b.T_world_imu.translation().z() - a.T_world_imu.translation().z(), 0.05);  // climbs ~8 cm
}

TEST(Preintegration, ResidualIsZeroAtThePredictionAndMovesWithAPerturbationOfStateJ) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(200.0), 1);
  const ImuBias bias{{0.01, -0.02, 0.005}, {0.1, 0.05, -0.2}};
  const Preintegrator pre = integrated(imu, kSec, 2 * kSec, ImuBias{});
  const NavState si = navStateAt(path, kSec);
  NavState sj = pre.predict(si, bias);
  EXPECT_LT(pre.residual(si, sj, bias).norm(), 1e-12);
  const Eigen::Vector3d dp(0.01, -0.02, 0.03), dv(-0.1, 0.2, 0.05), dphi(0.001, 0.002, -0.003);
  sj.T_world_imu.translation() += dp;
  sj.v_world += dv;
  sj.T_world_imu.linear() = sj.T_world_imu.linear() * geometry::expSO3(dphi);
  const Vector9d r = pre.residual(si, sj, bias);
  const Eigen::Matrix3d Rit = si.T_world_imu.linear().transpose();
  EXPECT_LT((r.segment<3>(0) - dphi).norm(), 1e-12);
  EXPECT_LT((r.segment<3>(3) - Rit * dv).norm(), 1e-12);
  EXPECT_LT((r.segment<3>(6) - Rit * dp).norm(), 1e-12);
}

TEST(Preintegration, BiasJacobiansEqualCentralDifferencesOfReintegration) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> imu = sim::simulateImu(path, noiseFree(200.0), 1);
  const ImuBias bias_hat{{0.003, -0.002, 0.001}, {0.05, -0.04, 0.02}};
  const Preintegrator pre = integrated(imu, kSec, 2 * kSec, bias_hat);
  const double h = 1e-5;
  Eigen::Matrix3d num_R_bg, num_V_bg, num_V_ba, num_P_bg, num_P_ba;
  for (int axis = 0; axis < 6; ++axis) {
    ImuBias plus = bias_hat, minus = bias_hat;
    Eigen::Vector3d& p = axis < 3 ? plus.gyro : plus.acc;
    Eigen::Vector3d& m = axis < 3 ? minus.gyro : minus.acc;
    p[axis % 3] += h;
    m[axis % 3] -= h;
    const Preintegrator a = integrated(imu, kSec, 2 * kSec, plus), b = integrated(imu, kSec, 2 * kSec, minus);
    const Eigen::Vector3d dR = (geometry::logSO3(pre.deltaR().transpose() * a.deltaR()) -
                                geometry::logSO3(pre.deltaR().transpose() * b.deltaR())) / (2 * h);
    const Eigen::Vector3d dV = (a.deltaV() - b.deltaV()) / (2 * h), dP = (a.deltaP() - b.deltaP()) / (2 * h);
    if (axis < 3) {
      num_R_bg.col(axis) = dR;
      num_V_bg.col(axis) = dV;
      num_P_bg.col(axis) = dP;
    } else {
      EXPECT_LT(dR.norm(), 1e-9);  // the accelerometer bias does not move the rotation
      num_V_ba.col(axis - 3) = dV;
      num_P_ba.col(axis - 3) = dP;
    }
  }
  const auto rel = [](const Eigen::Matrix3d& analytic, const Eigen::Matrix3d& numeric) {
    return (analytic - numeric).norm() / numeric.norm();
  };
  EXPECT_LT(rel(pre.dR_dbg(), num_R_bg), 1e-6) << pre.dR_dbg() << "\n" << num_R_bg;
  EXPECT_LT(rel(pre.dV_dbg(), num_V_bg), 1e-6) << pre.dV_dbg() << "\n" << num_V_bg;
  EXPECT_LT(rel(pre.dV_dba(), num_V_ba), 1e-6) << pre.dV_dba() << "\n" << num_V_ba;
  EXPECT_LT(rel(pre.dP_dbg(), num_P_bg), 1e-6) << pre.dP_dbg() << "\n" << num_P_bg;
  EXPECT_LT(rel(pre.dP_dba(), num_P_ba), 1e-6) << pre.dP_dba() << "\n" << num_P_ba;
  // Non-trivial: over 1 s the Jacobians are of order dt (rotation) and dt^2 / 2 (position).
  EXPECT_GT(pre.dR_dbg().norm(), 1.0);
  EXPECT_GT(pre.dP_dbg().norm(), 0.5);
}

TEST(Preintegration, CorrectedDeltasMatchReintegrationUnderAConstantBiasToFirstOrder) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> clean = sim::simulateImu(path, noiseFree(200.0), 1);
  const ImuBias bias{{0.02, -0.01, 0.015}, {0.2, -0.3, 0.1}};
  // Errors of the corrected deltas for the full and the half bias: [rotation, velocity, position].
  Eigen::Vector3d err_full, err_half, err_uncorrected;
  for (const double scale : {1.0, 0.5}) {
    const ImuBias b{scale * bias.gyro, scale * bias.acc};
    const std::vector<ImuSample> biased = withBias(clean, b);
    const Preintegrator at_zero = integrated(biased, kSec, 2 * kSec, ImuBias{});
    const Preintegrator exact = integrated(biased, kSec, 2 * kSec, b);  // re-integration at the true bias
    const Eigen::Vector3d err(angleBetween(at_zero.correctedDeltaR(b), exact.deltaR()),
                              (at_zero.correctedDeltaV(b) - exact.deltaV()).norm(),
                              (at_zero.correctedDeltaP(b) - exact.deltaP()).norm());
    (scale == 1.0 ? err_full : err_half) = err;
    if (scale == 1.0) {
      err_uncorrected << angleBetween(at_zero.deltaR(), exact.deltaR()), (at_zero.deltaV() - exact.deltaV()).norm(),
          (at_zero.deltaP() - exact.deltaP()).norm();
    }
  }
  std::printf("[ figures ] bias correction error rot/vel/pos %.3g rad %.3g m/s %.3g m (uncorrected %.3g %.3g %.3g)\n",
              err_full[0], err_full[1], err_full[2], err_uncorrected[0], err_uncorrected[1], err_uncorrected[2]);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(err_full[i], 0.02 * err_uncorrected[i]) << i;
    // Second-order remainder: halving the bias quarters it.
    EXPECT_NEAR(err_half[i] / err_full[i], 0.25, 0.05) << i;
  }
}

TEST(Preintegration, CovarianceMatchesMonteCarloStatisticsOfTheDeltasUnderWhiteNoise) {
  const sim::SplineTrajectory path = demandingPath();
  const std::vector<ImuSample> clean = sim::simulateImu(path, noiseFree(200.0), 1);
  const PreintegrationConfig config = quietConfig();
  const Time t0 = kSec, t1 = 2 * kSec;
  const Preintegrator ref = integrated(clean, t0, t1, ImuBias{}, config);
  const double sg = config.gyro_noise_density * std::sqrt(200.0), sa = config.acc_noise_density * std::sqrt(200.0);
  const int runs = 2000;
  std::vector<Vector9d> errors;
  for (int run = 0; run < runs; ++run) {
    std::vector<ImuSample> noisy = clean;
    for (std::size_t k = 0; k < noisy.size(); ++k) {
      for (int c = 0; c < 3; ++c) {
        noisy[k].omega_imu[c] += sg * sim::standardNormal(sim::hashKeys(run, k, c));
        noisy[k].acc_imu[c] += sa * sim::standardNormal(sim::hashKeys(run, k, c + 3));
      }
    }
    const Preintegrator pre = integrated(noisy, t0, t1, ImuBias{}, config);
    Vector9d e;
    e << geometry::logSO3(ref.deltaR().transpose() * pre.deltaR()), pre.deltaV() - ref.deltaV(),
        pre.deltaP() - ref.deltaP();  // Forster Eq. 40: dR~ = dR Exp(dphi), dv~ = dv + ddv, dp~ = dp + ddp
    errors.push_back(e);
  }
  Matrix9d mc = Matrix9d::Zero();
  for (const Vector9d& e : errors) mc += e * e.transpose() / runs;  // zero-mean noise: no mean subtracted
  const Matrix9d& cov = ref.covariance();
  double worst_var = 0, worst_corr = 0, mahalanobis = 0;
  for (int i = 0; i < 9; ++i) {
    worst_var = std::max(worst_var, std::abs(mc(i, i) / cov(i, i) - 1));
    for (int j = 0; j < i; ++j) {
      worst_corr = std::max(worst_corr, std::abs(mc(i, j) - cov(i, j)) / std::sqrt(cov(i, i) * cov(j, j)));
    }
  }
  const Eigen::LLT<Matrix9d> llt(cov);
  for (const Vector9d& e : errors) mahalanobis += llt.matrixL().solve(e).squaredNorm() / runs;
  std::printf("[ figures ] covariance vs %d Monte-Carlo runs: worst variance ratio error %.3f, worst correlation "
              "error %.3f, mean Mahalanobis^2 %.3f (expected 9)\n", runs, worst_var, worst_corr, mahalanobis);
  // 2000 runs: standard error of a variance 3.2 %, of a correlation 0.022, of the mean Mahalanobis^2 0.095.
  EXPECT_LT(worst_var, 0.12);
  EXPECT_LT(worst_corr, 0.1);
  EXPECT_NEAR(mahalanobis, 9.0, 0.5);
}

TEST(Preintegration, IntegrateRangeCutsThePartialFirstAndLastIntervalsAtT0AndT1) {
  std::vector<ImuSample> imu;
  for (int k = 0; k < 5; ++k) {
    ImuSample s;
    s.t = k * kSec / 100;  // 100 Hz
    s.omega_imu = Eigen::Vector3d(0.1 * k, -0.2, 0.3 + 0.05 * k);
    s.acc_imu = Eigen::Vector3d(1.0 - 0.1 * k, 0.5 * k, 9.81);
    imu.push_back(s);
  }
  const Time t0 = 3'000'000, t1 = 27'000'000;  // 3 ms and 27 ms
  const Preintegrator range = integrated(imu, t0, t1, ImuBias{});
  Preintegrator manual(ImuBias{}, PreintegrationConfig{});
  manual.integrate(imu[0].omega_imu, imu[0].acc_imu, 0.007);
  manual.integrate(imu[1].omega_imu, imu[1].acc_imu, 0.010);
  manual.integrate(imu[2].omega_imu, imu[2].acc_imu, 0.007);
  EXPECT_NEAR(range.deltaTime(), 0.024, 1e-15);
  EXPECT_LT((range.deltaR() - manual.deltaR()).norm(), 1e-15);
  EXPECT_LT((range.deltaV() - manual.deltaV()).norm(), 1e-15);
  EXPECT_LT((range.deltaP() - manual.deltaP()).norm(), 1e-15);
  EXPECT_LT((range.covariance() - manual.covariance()).norm(), 1e-18);
  // Two consecutive ranges split at a sample time equal the union; t1 beyond the last sample holds it.
  Preintegrator split(ImuBias{}, PreintegrationConfig{});
  split.integrateRange(imu, t0, 20'000'000);
  split.integrateRange(imu, 20'000'000, t1);
  EXPECT_LT((split.deltaP() - range.deltaP()).norm(), 1e-15);
  EXPECT_LT((split.dP_dbg() - range.dP_dbg()).norm(), 1e-15);
  const Preintegrator beyond = integrated(imu, 45'000'000, 65'000'000, ImuBias{});
  EXPECT_NEAR(beyond.deltaTime(), 0.020, 1e-15);
  EXPECT_LT(angleBetween(beyond.deltaR(), geometry::expSO3(imu[4].omega_imu * 0.020)), 1e-15);
}

TEST(Preintegration, ConstantRateAndForceGiveTheClosedFormDeltas) {
  std::vector<ImuSample> turn(1), push(1);
  turn[0].omega_imu = Eigen::Vector3d(0.3, -0.2, 0.5);
  push[0].acc_imu = Eigen::Vector3d(0.4, -1.0, 9.81);
  const Preintegrator rot = integrated(turn, 0, 3 * kSec / 2, ImuBias{});
  EXPECT_LT(angleBetween(rot.deltaR(), geometry::expSO3(turn[0].omega_imu * 1.5)), 1e-12);
  Preintegrator lin(ImuBias{}, PreintegrationConfig{});
  for (int k = 0; k < 150; ++k) lin.integrate(Eigen::Vector3d::Zero(), push[0].acc_imu, 0.01);
  EXPECT_LT((lin.deltaV() - push[0].acc_imu * 1.5).norm(), 1e-12);
  EXPECT_LT((lin.deltaP() - 0.5 * push[0].acc_imu * 1.5 * 1.5).norm(), 1e-12);
}

TEST(Preintegration, RejectsUncoveredT0UnorderedSamplesBadDtAndInvalidConfig) {
  std::vector<ImuSample> imu(3);
  imu[0].t = 10;
  imu[1].t = 20;
  imu[2].t = 30;
  Preintegrator pre(ImuBias{}, PreintegrationConfig{});
  EXPECT_THROW(pre.integrateRange(imu, 5, 25), std::invalid_argument);   // no sample at or before t0
  EXPECT_THROW(pre.integrateRange(imu, 25, 15), std::invalid_argument);  // t1 < t0
  std::swap(imu[1], imu[2]);
  EXPECT_THROW(pre.integrateRange(imu, 10, 25), std::invalid_argument);
  EXPECT_THROW(pre.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(pre.integrate(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), std::nan("")), std::invalid_argument);
  EXPECT_EQ(pre.deltaTime(), 0.0);
  PreintegrationConfig c;
  EXPECT_EQ(c.validate(), "");
  c.acc_noise_density = -1;
  EXPECT_NE(c.validate().find("acc_noise_density"), std::string::npos);
  EXPECT_THROW(Preintegrator(ImuBias{}, c), std::invalid_argument);
  c = PreintegrationConfig{};
  c.gravity = 0;
  EXPECT_NE(c.validate().find("gravity"), std::string::npos);
}
