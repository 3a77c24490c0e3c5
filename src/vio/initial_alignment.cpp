#include "vio/initial_alignment.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "geometry/so3.hpp"

namespace drover::vio {

namespace {

std::string fmt(double value, int precision = 2) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(precision);
  out << value;
  return out.str();
}

// The stacked linear system of the alignment, unknowns x = [v_0 .. v_{n-1} (each in its IMU frame), g_l, s].
// With R_k = R_l_imu_k, camera positions c_k (visual scale) and the IMU position p_k = s c_k - R_k t_bc, Drover's
// preintegration (Forster Eq. 38 with g the gravity acceleration, pointing down) gives per pair i -> j:
//   dp_ij = R_i^T (p_j - p_i - v_i dt - 1/2 g dt^2)
//     => -dt v_i - 1/2 dt^2 R_i^T g + R_i^T (c_j - c_i) s = dp_ij + R_i^T R_j t_bc - t_bc
//   dv_ij = R_i^T (v_j - v_i - g dt)
//     => -v_i + R_i^T R_j v_j - dt R_i^T g = dv_ij
// (VINS-Mono Eq. 10-11 with its positive-up G and its v in the body frame.)
void buildSystem(const std::vector<Eigen::Matrix3d>& R, const std::vector<Eigen::Vector3d>& c,
                 const Eigen::Vector3d& t_bc, const std::vector<imu::Preintegrator>& pre, Eigen::MatrixXd& A,
                 Eigen::VectorXd& b) {
  const int n = static_cast<int>(R.size());
  A.setZero(6 * (n - 1), 3 * n + 4);
  b.setZero(6 * (n - 1));
  const int g_col = 3 * n, s_col = 3 * n + 3;
  for (int i = 0; i + 1 < n; ++i) {
    const int j = i + 1, row = 6 * i;
    const double dt = pre[i].deltaTime();
    const Eigen::Matrix3d Ri_t = R[i].transpose();
    A.block<3, 3>(row, 3 * i) = -dt * Eigen::Matrix3d::Identity();
    A.block<3, 3>(row, g_col) = -0.5 * dt * dt * Ri_t;
    A.block<3, 1>(row, s_col) = Ri_t * (c[j] - c[i]);
    b.segment<3>(row) = pre[i].deltaP() + Ri_t * R[j] * t_bc - t_bc;
    A.block<3, 3>(row + 3, 3 * i) = -Eigen::Matrix3d::Identity();
    A.block<3, 3>(row + 3, 3 * j) = Ri_t * R[j];
    A.block<3, 3>(row + 3, g_col) = -dt * Ri_t;
    b.segment<3>(row + 3) = pre[i].deltaV();
  }
}

// Least squares through column-pivoted QR: the unknowns have different units (m/s, m/s^2, m per SfM unit).
Eigen::VectorXd solveLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  return A.colPivHouseholderQr().solve(b);
}

// Standard error of the last unknown of the least squares A x = b from its residuals (Gauss-Markov, rows of
// equal noise): sigma^2 = |A x - b|^2 / (rows - cols), var(x_last) = sigma^2 [(A^T A)^-1]_last,last.
double lastUnknownSigma(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& x) {
  const Eigen::Index dof = A.rows() - A.cols();
  if (dof <= 0) return std::numeric_limits<double>::infinity();
  const double sigma2 = (A * x - b).squaredNorm() / static_cast<double>(dof);
  const Eigen::MatrixXd N = A.transpose() * A;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(N);
  if (qr.rank() < N.cols()) return std::numeric_limits<double>::infinity();
  Eigen::VectorXd e = Eigen::VectorXd::Zero(N.cols());
  e(e.size() - 1) = 1;
  const double var = sigma2 * qr.solve(e)(e.size() - 1);
  return var >= 0 && std::isfinite(var) ? std::sqrt(var) : std::numeric_limits<double>::infinity();
}

LinearAlignment unpack(const Eigen::VectorXd& x, int n, const Eigen::Vector3d& g) {
  LinearAlignment out;
  for (int k = 0; k < n; ++k) out.v_imu.push_back(x.segment<3>(3 * k));
  out.g_l = g;
  out.scale = x(x.size() - 1);
  return out;
}

// Two unit vectors orthogonal to g (VINS-Mono TangentBasis).
Eigen::Matrix<double, 3, 2> tangentBasis(const Eigen::Vector3d& g) {
  const Eigen::Vector3d a = g.normalized();
  Eigen::Vector3d tmp(0, 0, 1);
  if ((a - tmp).norm() < 1e-6 || (a + tmp).norm() < 1e-6) tmp = Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d b1 = (tmp - a * a.dot(tmp)).normalized();
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = b1;
  B.col(1) = a.cross(b1);
  return B;
}

std::vector<ImuSample> mergedSamples(const std::vector<InitFrame>& frames) {
  std::vector<ImuSample> all;
  for (const auto& f : frames) all.insert(all.end(), f.imu.begin(), f.imu.end());
  std::stable_sort(all.begin(), all.end(), [](const ImuSample& a, const ImuSample& b) { return a.t < b.t; });
  all.erase(std::unique(all.begin(), all.end(), [](const ImuSample& a, const ImuSample& b) { return a.t == b.t; }),
            all.end());
  return all;
}

}  // namespace

std::string AlignmentConfig::validate() const {
  std::ostringstream out;
  out << sfm.validate();
  if (!(min_acc_excitation >= 0)) out << "min_acc_excitation = " << min_acc_excitation << " must be >= 0; ";
  if (!(max_gravity_error > 0)) out << "max_gravity_error = " << max_gravity_error << " must be > 0; ";
  if (!(min_scale >= 0) || !std::isfinite(min_scale)) out << "min_scale = " << min_scale << " must be >= 0; ";
  if (!(max_scale_rel_sigma > 0)) out << "max_scale_rel_sigma = " << max_scale_rel_sigma << " must be > 0; ";
  if (gyro_bias_iterations < 1) out << "gyro_bias_iterations = " << gyro_bias_iterations << " must be >= 1; ";
  if (refine_gravity_iterations < 1) {
    out << "refine_gravity_iterations = " << refine_gravity_iterations << " must be >= 1; ";
  }
  return out.str();
}

std::vector<imu::Preintegrator> preintegrateWindow(const std::vector<InitFrame>& frames, const imu::ImuBias& bias,
                                                   const imu::PreintegrationConfig& imu_config, bool midpoint) {
  std::vector<ImuSample> samples = mergedSamples(frames);
  if (samples.empty()) throw std::invalid_argument("preintegrateWindow: no IMU sample in the window");
  if (midpoint) {
    // Mid-point rule (VINS-Mono IntegrationBase::midPointIntegration, here on the raw signals): the interval
    // [t_k, t_k+1] gets (s_k + s_k+1) / 2, second-order accurate for samples of the instantaneous signal.
    // The specific force at t_k+1 is turned into the IMU frame at t_k, so that the preintegrator's
    // dR_ik f dt equals VINS-Mono's 1/2 (dR_ik a_k + dR_ik+1 a_k+1) dt.
    for (std::size_t k = 0; k + 1 < samples.size(); ++k) {
      const double dt = toSeconds(samples[k + 1].t - samples[k].t);
      const Eigen::Vector3d w = 0.5 * (samples[k].omega_imu + samples[k + 1].omega_imu);
      samples[k].omega_imu = w;
      samples[k].acc_imu =
          0.5 * (samples[k].acc_imu + geometry::expSO3((w - bias.gyro) * dt) * (samples[k + 1].acc_imu - bias.acc)) +
          0.5 * bias.acc;
    }
  }
  // The first frame's samples are empty by contract: the first sample is held back to the first camera stamp.
  if (samples.front().t > frames.front().t) {
    ImuSample first = samples.front();
    first.t = frames.front().t;
    samples.insert(samples.begin(), first);
  }
  std::vector<imu::Preintegrator> out;
  for (std::size_t k = 0; k + 1 < frames.size(); ++k) {
    out.emplace_back(bias, imu_config);
    out.back().integrateRange(samples, frames[k].t, frames[k + 1].t);
  }
  return out;
}

double accelerationExcitation(const std::vector<imu::Preintegrator>& preintegrations) {
  std::vector<Eigen::Vector3d> a;
  for (const auto& p : preintegrations) a.push_back(p.deltaV() / p.deltaTime());
  return spreadAboutMean(a);
}

double spreadAboutMean(const std::vector<Eigen::Vector3d>& values) {
  if (values.size() < 2) return 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : values) mean += x;
  mean /= static_cast<double>(values.size());
  double var = 0;
  for (const auto& x : values) var += (x - mean).squaredNorm();
  return std::sqrt(var / static_cast<double>(values.size()));
}

Eigen::Vector3d solveGyroscopeBias(const std::vector<Eigen::Matrix3d>& R_l_imu,
                                   const std::vector<imu::Preintegrator>& preintegrations) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k + 1 < R_l_imu.size(); ++k) {
    const auto& p = preintegrations[k];
    // dR(bg_hat + dbg) ~= dR Exp(J dbg) (Forster Eq. 44) should equal the SfM's R_k^T R_k+1.
    const Eigen::Vector3d r = geometry::logSO3(p.deltaR().transpose() * R_l_imu[k].transpose() * R_l_imu[k + 1]);
    H += p.dR_dbg().transpose() * p.dR_dbg();
    g += p.dR_dbg().transpose() * r;
  }
  return H.ldlt().solve(g);
}

namespace {

// The system in the inverse scale (AlignmentConfig::inverse_scale says why): the unknowns u_k = v_k / s,
// h = g / s and lambda = 1 / s; the SfM positions move to the right-hand side and lambda's column is the IMU's.
// Every column of A then holds IMU quantities (and the rotations), the SfM's position noise only b.
void invertSystem(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, Eigen::MatrixXd& A_inv, Eigen::VectorXd& b_inv) {
  const Eigen::Index s_col = A.cols() - 1;
  A_inv = A;
  A_inv.col(s_col) = -b;
  b_inv = -A.col(s_col);
}

}  // namespace

LinearAlignment linearAlignment(const std::vector<Eigen::Matrix3d>& R_l_imu, const std::vector<Eigen::Vector3d>& p_l_cam,
                                const Eigen::Vector3d& p_imu_cam, const std::vector<imu::Preintegrator>& preintegrations,
                                bool inverse_scale) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  buildSystem(R_l_imu, p_l_cam, p_imu_cam, preintegrations, A, b);
  const int n = static_cast<int>(R_l_imu.size());
  if (!inverse_scale) {
    const Eigen::VectorXd x = solveLeastSquares(A, b);
    return unpack(x, n, x.segment<3>(3 * n));
  }
  Eigen::MatrixXd A_inv;
  Eigen::VectorXd b_inv;
  invertSystem(A, b, A_inv, b_inv);
  const Eigen::VectorXd y = solveLeastSquares(A_inv, b_inv);
  const double lambda = y(y.size() - 1);
  Eigen::VectorXd x = y / lambda;
  x(x.size() - 1) = 1 / lambda;
  return unpack(x, n, x.segment<3>(3 * n));
}

LinearAlignment refineGravity(const std::vector<Eigen::Matrix3d>& R_l_imu, const std::vector<Eigen::Vector3d>& p_l_cam,
                              const Eigen::Vector3d& p_imu_cam, const std::vector<imu::Preintegrator>& preintegrations,
                              const Eigen::Vector3d& g0_in, double gravity, int iterations, bool inverse_scale) {
  Eigen::MatrixXd A;
  Eigen::VectorXd b;
  buildSystem(R_l_imu, p_l_cam, p_imu_cam, preintegrations, A, b);
  if (inverse_scale) invertSystem(Eigen::MatrixXd(A), Eigen::VectorXd(b), A, b);
  const int n = static_cast<int>(R_l_imu.size());
  const Eigen::MatrixXd A_g = A.middleCols(3 * n, 3);
  const Eigen::VectorXd A_s = A.col(3 * n + 3);
  // Unknowns [v (3n), w (2), s]: the scale last, for its sigma.
  const int s_col = 3 * n + 2;
  Eigen::MatrixXd A_r(A.rows(), s_col + 1);
  A_r.leftCols(3 * n) = A.leftCols(3 * n);
  Eigen::Vector3d g0 = g0_in.normalized() * gravity;
  Eigen::VectorXd x;
  double rel_sigma = std::numeric_limits<double>::infinity();
  double scale = 0;
  for (int it = 0; it < iterations; ++it) {
    // g = g0 + B w with w in the tangent plane of the sphere |g| = G (VINS-Mono Sec. V-B-3). In the inverse scale
    // h = lambda g = lambda g0 + B w' with w' = lambda w: still linear, g0's share moves into lambda's column.
    const Eigen::Matrix<double, 3, 2> B = tangentBasis(g0);
    A_r.middleCols(3 * n, 2) = A_g * B;
    Eigen::VectorXd rhs = b;
    if (inverse_scale) {
      A_r.col(s_col) = A_s + A_g * g0;
    } else {
      A_r.col(s_col) = A_s;
      rhs -= A_g * g0;
    }
    x = solveLeastSquares(A_r, rhs);
    const double last = x(s_col);
    if (inverse_scale) x /= last;  // u -> v, w' -> w; the scale is 1 / lambda
    g0 = (g0 + B * x.segment<2>(3 * n)).normalized() * gravity;
    scale = inverse_scale ? 1 / last : last;
    // The relative standard error of s equals that of lambda to first order (x as solved: undo the division).
    if (it + 1 == iterations) {
      rel_sigma = lastUnknownSigma(A_r, rhs, inverse_scale ? Eigen::VectorXd(x * last) : x) / std::abs(last);
    }
  }
  LinearAlignment out = unpack(x, n, g0);
  out.scale = scale;
  out.scale_sigma = rel_sigma * std::abs(scale);
  return out;
}

namespace {

// Step (h): the world frame. R_w_l turns g_l onto (0, 0, -G), then about z so the IMU of frame 0 has yaw 0;
// positions are metric IMU positions relative to frame 0 (VINS-Mono visualInitialAlign after the alignment).
void toWorld(const std::vector<Eigen::Matrix3d>& R_l_imu, const std::vector<Eigen::Vector3d>& p_l_cam,
             const Eigen::Vector3d& t_bc, const LinearAlignment& la, const SfmResult& sfm, AlignmentResult& out) {
  Eigen::Matrix3d R_w_l =
      Eigen::Quaterniond::FromTwoVectors(la.g_l.normalized(), Eigen::Vector3d(0, 0, -1)).toRotationMatrix();
  R_w_l = Eigen::AngleAxisd(-geometry::yawOf(R_w_l * R_l_imu[0]), Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_w_l;
  const auto imuPosition = [&](std::size_t k) { return Eigen::Vector3d(la.scale * p_l_cam[k] - R_l_imu[k] * t_bc); };
  const Eigen::Vector3d p0_l = imuPosition(0);
  for (std::size_t k = 0; k < R_l_imu.size(); ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = geometry::orthonormalize(R_w_l * R_l_imu[k]);
    T.translation() = R_w_l * (imuPosition(k) - p0_l);
    out.T_world_imu.push_back(T);
    out.v_world.push_back(T.linear() * la.v_imu[k]);
  }
  for (const auto& [id, p] : sfm.points_l) out.points_world[id] = R_w_l * (la.scale * p - p0_l);
}

AlignmentResult refuse(AlignmentResult result, const std::string& why) {
  result.ok = false;
  result.why = why;
  return result;
}

}  // namespace

AlignmentResult alignVisualInertial(const std::vector<InitFrame>& frames, const Eigen::Isometry3d& T_imu_cam,
                                    const imu::PreintegrationConfig& imu_config, const AlignmentConfig& config) {
  const std::string error = config.validate();
  if (!error.empty()) throw std::invalid_argument("AlignmentConfig: " + error);
  AlignmentResult result;
  if (frames.size() < 3) return refuse(result, "window: " + std::to_string(frames.size()) + " frames < 3");
  for (std::size_t k = 1; k < frames.size(); ++k) {
    if (frames[k].t <= frames[k - 1].t) return refuse(result, "window: frame stamps not increasing at frame " + std::to_string(k));
  }
  if (mergedSamples(frames).empty()) return refuse(result, "imu: no IMU sample in the window");

  // (a) Excitation: the frame-to-frame average accelerations must vary (VINS-Mono initialStructure).
  imu::ImuBias bias;
  std::vector<imu::Preintegrator> pre = preintegrateWindow(frames, bias, imu_config, config.imu_midpoint);
  result.acc_excitation = accelerationExcitation(pre);
  if (result.acc_excitation < config.min_acc_excitation) {
    return refuse(result, "excitation: not enough motion, acceleration std " + fmt(result.acc_excitation, 3) +
                              " m/s^2 < " + fmt(config.min_acc_excitation, 3) + " m/s^2");
  }

  // (b, c) Vision-only structure from motion in camera l.
  std::vector<FrameFeatures> features;
  for (const auto& f : frames) features.push_back(f.features);
  const SfmResult sfm = globalSfm(features, config.sfm);
  result.l = sfm.l;
  if (!sfm.ok) return refuse(result, sfm.why);
  const Eigen::Matrix3d R_bc = T_imu_cam.linear();
  const Eigen::Vector3d t_bc = T_imu_cam.translation();
  std::vector<Eigen::Matrix3d> R_l_imu;
  std::vector<Eigen::Vector3d> p_l_cam;
  for (const auto& T : sfm.T_l_cam) {
    R_l_imu.push_back(T.linear() * R_bc.transpose());
    p_l_cam.push_back(T.translation());
  }

  // (d) Gyroscope bias, then the preintegrations again at the new bias.
  for (int it = 0; it < config.gyro_bias_iterations; ++it) {
    bias.gyro += solveGyroscopeBias(R_l_imu, pre);
    pre = preintegrateWindow(frames, bias, imu_config, config.imu_midpoint);
  }
  result.gyro_bias = bias.gyro;
  if (!bias.gyro.allFinite()) return refuse(result, "gyro bias: not finite");

  // (e) Linear alignment, (f) gravity refined on |g| = G, (g) checks.
  const double G = imu_config.gravity;
  const bool inverse = config.inverse_scale;
  const LinearAlignment coarse = linearAlignment(R_l_imu, p_l_cam, t_bc, pre, inverse);
  const double g_error = std::abs(coarse.g_l.norm() - G);
  if (!coarse.g_l.allFinite() || !(g_error <= config.max_gravity_error)) {
    return refuse(result, "linear alignment: |g| = " + fmt(coarse.g_l.norm()) + " m/s^2 is " + fmt(g_error) +
                              " m/s^2 off " + fmt(G) + " > " + fmt(config.max_gravity_error) + " m/s^2");
  }
  if (!(coarse.scale > config.min_scale)) {
    return refuse(result, "linear alignment: scale " + fmt(coarse.scale, 4) + " <= " + fmt(config.min_scale, 4));
  }
  const LinearAlignment la =
      refineGravity(R_l_imu, p_l_cam, t_bc, pre, coarse.g_l, G, config.refine_gravity_iterations, inverse);
  result.scale = la.scale;
  result.gravity_camera_l = la.g_l;
  bool finite = la.g_l.allFinite() && std::isfinite(la.scale);
  for (const auto& v : la.v_imu) finite = finite && v.allFinite();
  if (!finite) return refuse(result, "refine gravity: result not finite");
  if (!(la.scale > config.min_scale)) {
    return refuse(result, "refine gravity: scale " + fmt(la.scale, 4) + " <= " + fmt(config.min_scale, 4));
  }

  // (g') The scale must be determined: a window that cannot tell a forward acceleration from a tilt of gravity
  // (a steady acceleration without rotation: a car pulling away) returns a scale off by tens of percent.
  result.scale_rel_sigma = la.scale_sigma / la.scale;
  if (!(result.scale_rel_sigma <= config.max_scale_rel_sigma)) {
    return refuse(result, "refine gravity: scale " + fmt(la.scale, 3) + " not determined, +-" +
                              fmt(100 * result.scale_rel_sigma, 1) + " % > " +
                              fmt(100 * config.max_scale_rel_sigma, 1) +
                              " % (too little rotation or change of acceleration to tell acceleration from gravity)");
  }
  // (h) Gravity-aligned world frame.
  toWorld(R_l_imu, p_l_cam, t_bc, la, sfm, result);
  result.ok = true;
  return result;
}

}  // namespace drover::vio
