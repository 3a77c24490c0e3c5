#include "backend/schur_marginalizer.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "backend/quaternion_manifold.hpp"
#include "geometry/so3.hpp"

namespace drover::backend {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

int tangentSize(const MarginalBlock& b) { return b.manifold ? b.manifold->TangentSize() : b.ambient; }

// M = D^+ V S V^T D^+ with D = diag(d), d_i = M_ii^-1/2: the eigen-decomposition of the Jacobi-scaled D M D (unit
// diagonal), whose eigenvalues below eps * max are set to zero. Scaling first makes the rank decision independent of
// units: a window's information spans ~1e10 (bias random walk) to ~1e1 (a weakly seen velocity), and an unscaled
// relative threshold of 1e-8 would silently drop the latter; in the scaled matrix only (near-)degenerate directions
// such as the gauge have tiny eigenvalues. A coordinate whose diagonal is at the rounding level of the sums that
// formed M (<= n u max_i M_ii) is not scaled up but left out (d_i = 0): its information is indistinguishable from
// zero. Deterministic for a given input.
struct ScaledEigen {
  VectorXd d;
  MatrixXd V;
  VectorXd s;  // eigenvalues of D M D, zeroed below the threshold
  int rank = 0;
};

ScaledEigen scaledEigen(const MatrixXd& M, double eps) {
  ScaledEigen out;
  const double floor = static_cast<double>(M.rows()) * std::numeric_limits<double>::epsilon() *
                       std::max(M.rows() > 0 ? M.diagonal().maxCoeff() : 0.0, 0.0);
  out.d = M.diagonal().unaryExpr([floor](double h) { return h > floor ? 1.0 / std::sqrt(h) : 0.0; });
  if (M.rows() == 0) return out;
  const MatrixXd scaled = out.d.asDiagonal() * (0.5 * (M + M.transpose())) * out.d.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(scaled);
  out.V = eig.eigenvectors();
  out.s = eig.eigenvalues();
  const double threshold = eps * std::max(out.s.maxCoeff(), 0.0);
  for (Eigen::Index k = 0; k < out.s.size(); ++k) {
    if (out.s(k) > threshold && out.s(k) > 0.0) {
      ++out.rank;
    } else {
      out.s(k) = 0.0;
    }
  }
  return out;
}

// Ceres' robust-loss correction (ceres/internal/corrector.cc, Triggs et al., "Bundle adjustment -- a modern
// synthesis", 2000, Sec. 4.3): with s = |r|^2 and rho = [rho, rho', rho''],
//   J <- sqrt(rho') (I - alpha r r^T / s) J,   r <- sqrt(rho') / (1 - alpha) r,   alpha = 1 - sqrt(1 + 2 s rho'' / rho'),
// and alpha = 0 (plain sqrt(rho') scaling, as VINS-Mono does) when rho'' <= 0 or s = 0, so that J^T r = rho' J^T r
// and J^T J is the Gauss-Newton Hessian of rho. A residual with rho' <= 0 contributes nothing.
void applyLoss(const ceres::LossFunction& loss, VectorXd& r, std::vector<MatrixXd>& J) {
  const double sq_norm = r.squaredNorm();
  double rho[3];
  loss.Evaluate(sq_norm, rho);
  const double sqrt_rho1 = std::sqrt(std::max(rho[1], 0.0));
  double residual_scaling = sqrt_rho1, alpha_sq_norm = 0.0;
  if (sq_norm > 0.0 && rho[1] > 0.0 && rho[2] > 0.0) {
    const double alpha = 1.0 - std::sqrt(1.0 + 2.0 * sq_norm * rho[2] / rho[1]);
    residual_scaling = sqrt_rho1 / (1.0 - alpha);
    alpha_sq_norm = alpha / sq_norm;
  }
  for (auto& Jk : J) Jk = sqrt_rho1 * (Jk - alpha_sq_norm * r * (r.transpose() * Jk));
  r *= residual_scaling;
}

}  // namespace

SchurMarginalizer::SchurMarginalizer(double relative_eigen_threshold) : eps_(relative_eigen_threshold) {
  if (!std::isfinite(eps_) || eps_ < 0.0 || eps_ >= 1.0) {
    throw std::invalid_argument("SchurMarginalizer: relative_eigen_threshold must be in [0, 1)");
  }
}

void SchurMarginalizer::addBlock(double* data, int ambient_size, const ceres::Manifold* manifold) {
  if (data == nullptr || ambient_size < 1) {
    throw std::invalid_argument("SchurMarginalizer::addBlock: null block or ambient size < 1");
  }
  if (manifold != nullptr && manifold->AmbientSize() != ambient_size) {
    throw std::invalid_argument("SchurMarginalizer::addBlock: the manifold's ambient size differs from the block's");
  }
  const auto it = index_.find(data);
  if (it != index_.end()) {
    const MarginalBlock& b = blocks_[static_cast<std::size_t>(it->second)];
    if (b.ambient != ambient_size || b.manifold != manifold) {
      throw std::invalid_argument("SchurMarginalizer::addBlock: block declared again with another size or manifold");
    }
    return;
  }
  index_.emplace(data, static_cast<int>(blocks_.size()));
  blocks_.push_back({data, ambient_size, manifold});
}

void SchurMarginalizer::addResidual(const ceres::CostFunction* cost, const ceres::LossFunction* loss,
                                    std::vector<double*> blocks) {
  if (cost == nullptr) throw std::invalid_argument("SchurMarginalizer::addResidual: null cost");
  const std::vector<int32_t>& sizes = cost->parameter_block_sizes();
  if (sizes.size() != blocks.size()) {
    throw std::invalid_argument("SchurMarginalizer::addResidual: block count differs from the cost's");
  }
  Residual res{cost, loss, {}};
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    const auto it = index_.find(blocks[k]);
    if (it == index_.end()) throw std::invalid_argument("SchurMarginalizer::addResidual: undeclared parameter block");
    if (blocks_[static_cast<std::size_t>(it->second)].ambient != sizes[k]) {
      throw std::invalid_argument("SchurMarginalizer::addResidual: block size differs from the cost's");
    }
    if (std::find(res.blocks.begin(), res.blocks.end(), it->second) != res.blocks.end()) {
      throw std::invalid_argument("SchurMarginalizer::addResidual: a block appears twice in one residual");
    }
    res.blocks.push_back(it->second);
  }
  residuals_.push_back(std::move(res));
}

namespace {

// One residual block's whitened, loss-corrected residual and tangent Jacobians at the blocks' current values.
bool linearizeResidual(const ceres::CostFunction& cost, const ceres::LossFunction* loss,
                       const std::vector<const MarginalBlock*>& blocks, VectorXd& r, std::vector<MatrixXd>& J) {
  const int n = cost.num_residuals();
  std::vector<const double*> params;
  std::vector<RowMatrix> ambient;
  std::vector<double*> jac_ptrs;
  for (const MarginalBlock* b : blocks) {
    params.push_back(b->data);
    ambient.emplace_back(n, b->ambient);
  }
  for (auto& a : ambient) jac_ptrs.push_back(a.data());
  r.resize(n);
  if (!cost.Evaluate(params.data(), r.data(), jac_ptrs.data())) return false;
  J.clear();
  for (std::size_t k = 0; k < blocks.size(); ++k) {
    if (blocks[k]->manifold == nullptr) {
      J.emplace_back(ambient[k]);
      continue;
    }
    RowMatrix plus(blocks[k]->ambient, blocks[k]->manifold->TangentSize());
    if (!blocks[k]->manifold->PlusJacobian(blocks[k]->data, plus.data())) return false;
    J.emplace_back(ambient[k] * plus);
  }
  if (!r.allFinite() || !std::all_of(J.begin(), J.end(), [](const MatrixXd& m) { return m.allFinite(); })) {
    return false;
  }
  if (loss != nullptr) applyLoss(*loss, r, J);
  return r.allFinite() && std::all_of(J.begin(), J.end(), [](const MatrixXd& m) { return m.allFinite(); });
}

// Eliminates first the dropped one-dimensional coordinates that no residual couples to another dropped coordinate
// (a VIO window's inverse depths: each meets only frame states): their block of H is diagonal, so their Schur
// complement is exact and costs O(m k^2) instead of the O(m^3) eigen-decomposition of the whole dropped block. A
// coordinate whose diagonal is at the rounding level (nothing constrains it) is left out, as the pseudo-inverse
// would. H and g are [dropped (m) | kept] on entry and are replaced by the reduced system, m by the dropped left.
void eliminateDecoupledScalars(MatrixXd& H, VectorXd& g, int& m) {
  if (m == 0) return;
  const double floor = static_cast<double>(H.rows()) * std::numeric_limits<double>::epsilon() *
                       std::max(H.diagonal().head(m).maxCoeff(), 0.0);
  std::vector<int> scalar, rest;
  for (int c = 0; c < m; ++c) {
    bool decoupled = true;
    for (int j = 0; j < m && decoupled; ++j) decoupled = j == c || H(c, j) == 0.0;
    (decoupled ? scalar : rest).push_back(c);
  }
  if (scalar.empty()) return;
  const int n = static_cast<int>(H.rows());
  std::vector<int> keep = rest;  // the reduced system: the other dropped coordinates, then the kept ones
  for (int c = m; c < n; ++c) keep.push_back(c);
  const int r = static_cast<int>(keep.size());
  MatrixXd Hr(r, r), C(r, static_cast<int>(scalar.size()));
  VectorXd gr(r);
  for (int a = 0; a < r; ++a) {
    gr(a) = g(keep[a]);
    for (int b = 0; b < r; ++b) Hr(a, b) = H(keep[a], keep[b]);
  }
  for (std::size_t s = 0; s < scalar.size(); ++s) {
    const double h = H(scalar[s], scalar[s]);
    const double inv_sqrt = h > floor ? 1.0 / std::sqrt(h) : 0.0;
    for (int a = 0; a < r; ++a) C(a, static_cast<int>(s)) = H(keep[a], scalar[s]) * inv_sqrt;
    if (inv_sqrt > 0.0) gr.noalias() -= C.col(static_cast<int>(s)) * (g(scalar[s]) * inv_sqrt);
  }
  Hr.noalias() -= C * C.transpose();  // H_rr - H_rs H_ss^-1 H_sr with H_ss diagonal
  H = std::move(Hr);
  g = std::move(gr);
  m = static_cast<int>(rest.size());
}

MarginalResult failure(std::string reason) {
  MarginalResult out;
  out.reason = "marginalisation: " + std::move(reason);
  return out;
}

}  // namespace

MarginalResult SchurMarginalizer::marginalize(const std::set<const double*>& drop) const {
  for (const double* d : drop) {
    if (index_.count(d) == 0) throw std::invalid_argument("SchurMarginalizer::marginalize: undeclared dropped block");
  }
  // Tangent columns: touched dropped blocks first, then touched kept blocks, each in declaration order.
  std::vector<bool> touched(blocks_.size(), false);
  for (const auto& res : residuals_) {
    for (const int b : res.blocks) touched[static_cast<std::size_t>(b)] = true;
  }
  std::vector<int> column(blocks_.size(), -1);
  std::vector<int> kept;
  int m = 0, n = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      if (!touched[b] || (drop.count(blocks_[b].data) == 1) != (pass == 0)) continue;
      column[b] = n;
      n += tangentSize(blocks_[b]);
      if (pass == 1) kept.push_back(static_cast<int>(b));
    }
    if (pass == 0) m = n;
  }
  if (kept.empty()) return failure("no kept block is touched by a residual");

  // H = sum J^T J, g = sum J^T r, accumulated per residual block (Qin et al. 2018, Eq. 29 before the Schur step).
  MatrixXd H = MatrixXd::Zero(n, n);
  VectorXd g = VectorXd::Zero(n);
  VectorXd r;
  std::vector<MatrixXd> J;
  for (std::size_t i = 0; i < residuals_.size(); ++i) {
    const Residual& res = residuals_[i];
    std::vector<const MarginalBlock*> blocks;
    for (const int b : res.blocks) blocks.push_back(&blocks_[static_cast<std::size_t>(b)]);
    if (!linearizeResidual(*res.cost, res.loss, blocks, r, J)) {
      return failure("residual block " + std::to_string(i) + " failed to evaluate or gave non-finite values");
    }
    for (std::size_t a = 0; a < res.blocks.size(); ++a) {
      const int ca = column[static_cast<std::size_t>(res.blocks[a])];
      g.segment(ca, J[a].cols()).noalias() += J[a].transpose() * r;
      for (std::size_t c = a; c < res.blocks.size(); ++c) {
        const int cc = column[static_cast<std::size_t>(res.blocks[c])];
        const MatrixXd block = J[a].transpose() * J[c];
        H.block(ca, cc, block.rows(), block.cols()) += block;
        if (c != a) H.block(cc, ca, block.cols(), block.rows()) += block.transpose();
      }
    }
  }

  eliminateDecoupledScalars(H, g, m);
  n = static_cast<int>(H.rows());

  // Schur complement with the pseudo-inverse H_mm^+ = D V S^+ V^T D (a dropped direction nothing constrains adds
  // nothing; Qin et al. 2018, Eq. 30).
  const int k = n - m;
  MatrixXd A = H.bottomRightCorner(k, k);
  VectorXd b = g.tail(k);
  if (m > 0) {
    const ScaledEigen e = scaledEigen(H.topLeftCorner(m, m), eps_);
    const VectorXd s_inv = (e.s.array() > 0.0).select(e.s.cwiseInverse(), 0.0);
    const MatrixXd H_km_DV = H.bottomLeftCorner(k, m) * e.d.asDiagonal() * e.V;
    A.noalias() -= H_km_DV * s_inv.asDiagonal() * H_km_DV.transpose();
    b.noalias() -= H_km_DV * (s_inv.asDiagonal() * (e.V.transpose() * e.d.asDiagonal() * g.head(m)));
  }

  // A = D^+ V S V^T D^+ -> L = sqrt(S) V^T D^+, offset = sqrt(S)^+ V^T D b over the rank non-zero eigenvalues:
  // L^T L = A and L^T offset = b (b lies in A's range, being a Schur complement of a PSD H's gradient).
  const ScaledEigen e = scaledEigen(A, eps_);
  MarginalResult out;
  out.rank = e.rank;
  out.sqrt_information.resize(e.rank, k);
  out.offset.resize(e.rank);
  const VectorXd d_inv = e.d.unaryExpr([](double d) { return d > 0.0 ? 1.0 / d : 0.0; });
  const VectorXd d_b = e.d.cwiseProduct(b);
  int row = 0;
  for (Eigen::Index j = 0; j < e.s.size(); ++j) {
    if (e.s(j) <= 0.0) continue;
    const double sqrt_s = std::sqrt(e.s(j));
    out.sqrt_information.row(row) = sqrt_s * e.V.col(j).cwiseProduct(d_inv).transpose();
    out.offset(row) = e.V.col(j).dot(d_b) / sqrt_s;
    ++row;
  }
  if (!out.sqrt_information.allFinite() || !out.offset.allFinite()) {
    return failure("the Schur complement is not finite");
  }
  if (out.rank == 0) return failure("the Schur complement on the kept blocks is zero (nothing constrains them)");
  for (const int kb : kept) {
    const MarginalBlock& blk = blocks_[static_cast<std::size_t>(kb)];
    out.kept.push_back(blk.data);
    out.ambient_sizes.push_back(blk.ambient);
    out.tangent_sizes.push_back(tangentSize(blk));
    out.manifolds.push_back(blk.manifold);
    out.linearization.emplace_back(blk.data, blk.data + blk.ambient);
  }
  out.ok = true;
  return out;
}

namespace {

// T = d Minus(Plus(x, d), x_lin) / d d at d = 0 for a manifold other than the two with closed forms: central
// differences with a step that keeps the truncation error ~h^2 (the Minus of a smooth manifold is smooth).
bool minusTangentJacobian(const ceres::Manifold& manifold, const double* x, const double* x_lin, MatrixXd& T) {
  constexpr double kStep = 1e-6;
  const int t = manifold.TangentSize();
  std::vector<double> plus(static_cast<std::size_t>(manifold.AmbientSize())), minus(plus.size());
  VectorXd d = VectorXd::Zero(t), r_plus(t), r_minus(t);
  T.resize(t, t);
  for (int j = 0; j < t; ++j) {
    d(j) = kStep;
    const bool ok_plus = manifold.Plus(x, d.data(), plus.data()) && manifold.Minus(plus.data(), x_lin, r_plus.data());
    d(j) = -kStep;
    const bool ok_minus =
        manifold.Plus(x, d.data(), minus.data()) && manifold.Minus(minus.data(), x_lin, r_minus.data());
    d(j) = 0.0;
    if (!ok_plus || !ok_minus) return false;
    T.col(j) = (r_plus - r_minus) / (2.0 * kStep);
  }
  return true;
}

}  // namespace

MarginalPriorFactor::MarginalPriorFactor(MarginalResult result) : result_(std::move(result)) {
  const MarginalResult& r = result_;
  const std::size_t nb = r.kept.size();
  if (!r.ok) throw std::invalid_argument("MarginalPriorFactor: marginalisation failed: " + r.reason);
  if (nb == 0 || r.ambient_sizes.size() != nb || r.tangent_sizes.size() != nb || r.manifolds.size() != nb ||
      r.linearization.size() != nb || r.rank < 1 || r.sqrt_information.rows() != r.rank ||
      r.offset.size() != r.rank || !r.sqrt_information.allFinite() || !r.offset.allFinite()) {
    throw std::invalid_argument("MarginalPriorFactor: inconsistent or non-finite marginalisation result");
  }
  int columns = 0;
  for (std::size_t k = 0; k < nb; ++k) {
    const int expected_tangent = r.manifolds[k] ? r.manifolds[k]->TangentSize() : r.ambient_sizes[k];
    if (r.linearization[k].size() != static_cast<std::size_t>(r.ambient_sizes[k]) ||
        r.tangent_sizes[k] != expected_tangent) {
      throw std::invalid_argument("MarginalPriorFactor: block sizes disagree");
    }
    tangent_offset_.push_back(columns);
    columns += r.tangent_sizes[k];
    mutable_parameter_block_sizes()->push_back(r.ambient_sizes[k]);
  }
  if (r.sqrt_information.cols() != columns) {
    throw std::invalid_argument("MarginalPriorFactor: sqrt information has the wrong number of columns");
  }
  set_num_residuals(r.rank);
}

bool MarginalPriorFactor::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const MarginalResult& res = result_;
  const Eigen::Index total = res.sqrt_information.cols();
  VectorXd dx(total);
  for (std::size_t k = 0; k < res.kept.size(); ++k) {
    const int t = res.tangent_sizes[k], col = tangent_offset_[k];
    const double* lin = res.linearization[k].data();
    if (res.manifolds[k] == nullptr) {
      for (int i = 0; i < t; ++i) dx(col + i) = parameters[k][i] - lin[i];
    } else if (!res.manifolds[k]->Minus(parameters[k], lin, dx.data() + col)) {
      return false;
    }
  }
  Eigen::Map<VectorXd> r(residuals, res.rank);
  r = res.offset + res.sqrt_information * dx;
  if (jacobians == nullptr) return true;
  for (std::size_t k = 0; k < res.kept.size(); ++k) {
    if (jacobians[k] == nullptr) continue;
    const int t = res.tangent_sizes[k], a = res.ambient_sizes[k];
    const auto L_k = res.sqrt_information.middleCols(tangent_offset_[k], t);
    Eigen::Map<RowMatrix> J(jacobians[k], res.rank, a);
    const ceres::Manifold* manifold = res.manifolds[k];
    if (manifold == nullptr) {
      J = L_k;
      continue;
    }
    RowMatrix minus_jacobian(t, a);
    if (!manifold->MinusJacobian(parameters[k], minus_jacobian.data())) return false;
    MatrixXd T;
    if (dynamic_cast<const RightQuaternionManifold*>(manifold) != nullptr) {
      // Minus(x Exp(d), x_lin) = Log(R_lin^T R Exp(d)): derivative J_r^-1(dtheta) (Forster et al. 2017, Eq. 8).
      T = geometry::rightJacobianInverseSO3(Eigen::Vector3d(dx.segment<3>(tangent_offset_[k])));
    } else if (!minusTangentJacobian(*manifold, parameters[k], res.linearization[k].data(), T)) {
      return false;
    }
    J = L_k * T * minus_jacobian;
  }
  return true;
}

}  // namespace drover::backend
