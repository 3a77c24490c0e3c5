#include "backend/marginalization.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "backend/quaternion_manifold.hpp"

namespace drover::backend {

namespace {

using MatrixXd = Eigen::MatrixXd;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

constexpr std::array<int, 4> kAmbientSize = {3, 4, 3, 6};
constexpr std::array<int, 4> kTangentOffset = {0, 3, 6, 9};  // within one 15-dimensional state

// Stacks the whitened residuals and tangent Jacobians of every term: r (rows), J (rows x 30).
bool linearize(const std::vector<MarginalizationTerm>& terms, const std::array<double*, 8>& blocks, MatrixXd& J,
               Eigen::VectorXd& r) {
  int rows = 0;
  for (const auto& term : terms) rows += term.cost->num_residuals();
  J = MatrixXd::Zero(rows, 30);
  r = Eigen::VectorXd::Zero(rows);
  int row = 0;
  for (const auto& term : terms) {
    const int n = term.cost->num_residuals();
    std::vector<const double*> params;
    std::vector<RowMatrix> jac;
    std::vector<double*> jac_ptr;
    for (const int b : term.blocks) {
      params.push_back(blocks[b]);
      jac.emplace_back(n, kAmbientSize[b % 4]);
    }
    for (auto& j : jac) jac_ptr.push_back(j.data());
    Eigen::VectorXd res(n);
    if (!term.cost->Evaluate(params.data(), res.data(), jac_ptr.data())) return false;
    r.segment(row, n) = res;
    for (std::size_t k = 0; k < term.blocks.size(); ++k) {
      const int b = term.blocks[k];
      const int col = 15 * (b / 4) + kTangentOffset[b % 4];
      if (b % 4 == 1) {  // quaternion: ambient -> tangent through d Plus / d dtheta
        const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(blocks[b]).normalized();
        J.block(row, col, n, 3) = jac[k] * quaternionPlusJacobian(q);
      } else {
        J.block(row, col, n, kAmbientSize[b % 4]) = jac[k];
      }
    }
    row += n;
  }
  return J.allFinite() && r.allFinite();
}

// Pseudo-inverse of a symmetric positive semi-definite matrix (eigenvalues below a relative threshold dropped).
MatrixXd pseudoInverse(const MatrixXd& H) {
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(0.5 * (H + H.transpose()));
  const Eigen::VectorXd s = eig.eigenvalues();
  const double threshold = 1e-12 * std::max(s.maxCoeff(), 0.0);
  const Eigen::VectorXd s_inv = (s.array() > threshold).select(s.cwiseInverse(), 0.0);
  return eig.eigenvectors() * s_inv.asDiagonal() * eig.eigenvectors().transpose();
}

StatePoint statePointAt(const std::array<double*, 4>& x) {
  StatePoint s;
  s.p_world = Eigen::Map<const Eigen::Vector3d>(x[0]);
  s.q_world_imu = Eigen::Map<const Eigen::Quaterniond>(x[1]).normalized();
  s.v_world = Eigen::Map<const Eigen::Vector3d>(x[2]);
  s.bias = Eigen::Map<const Vector6d>(x[3]);
  return s;
}

}  // namespace

MarginalPrior marginalizeState(const std::vector<MarginalizationTerm>& terms, const std::array<double*, 4>& dropped,
                               const std::array<double*, 4>& kept) {
  MarginalPrior out;
  out.linearization = statePointAt(kept);
  const std::array<double*, 8> blocks = {dropped[0], dropped[1], dropped[2], dropped[3],
                                         kept[0],    kept[1],    kept[2],    kept[3]};
  MatrixXd J;
  Eigen::VectorXd r;
  if (!linearize(terms, blocks, J, r)) {
    out.reason = "marginalisation: a factor failed to evaluate or gave non-finite values";
    return out;
  }
  const MatrixXd H = J.transpose() * J;
  const Eigen::VectorXd g = J.transpose() * r;
  const MatrixXd H_mm_inv = pseudoInverse(H.topLeftCorner(15, 15));
  const MatrixXd H_rm = H.bottomLeftCorner(15, 15);
  const Matrix15d A = H.bottomRightCorner(15, 15) - H_rm * H_mm_inv * H_rm.transpose();
  const Vector15d b = g.tail(15) - H_rm * H_mm_inv * g.head(15);

  const Eigen::SelfAdjointEigenSolver<Matrix15d> eig(0.5 * (A + A.transpose()));
  const Vector15d s = eig.eigenvalues();
  const double threshold = 1e-12 * std::max(s.maxCoeff(), 0.0);
  Vector15d sqrt_s = Vector15d::Zero(), inv_sqrt_s = Vector15d::Zero();
  for (int k = 0; k < 15; ++k) {
    if (s(k) > threshold) {
      sqrt_s(k) = std::sqrt(s(k));
      inv_sqrt_s(k) = 1.0 / sqrt_s(k);
      ++out.rank;
    }
  }
  out.sqrt_information = sqrt_s.asDiagonal() * eig.eigenvectors().transpose();
  out.offset = inv_sqrt_s.asDiagonal() * eig.eigenvectors().transpose() * b;
  if (!out.sqrt_information.allFinite() || !out.offset.allFinite()) {
    out.reason = "marginalisation: the Schur complement is not finite";
    return out;
  }
  out.ok = true;
  return out;
}

}  // namespace drover::backend
