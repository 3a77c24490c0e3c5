#pragma once
// General marginalisation by the Schur complement for a sliding-window estimator with any parameter blocks (the
// construction of VINS-Mono's MarginalizationInfo / MarginalizationFactor, Qin, Li, Shen, T-RO 2018, Sec. VI-D;
// Sibley, Matthies, Sukhatme, JFR 2010). marginalizeState() (marginalization.hpp) is the fixed-size special case
// for one navigation state of the lidar smoother; this one takes arbitrary blocks, manifolds and robust losses.
//
// Every residual block handed over is linearised at the blocks' current values in the tangent space
// (J = J_ambient * PlusJacobian, robust loss applied as Ceres applies it), giving H = J^T J and g = J^T r with the
// dropped blocks m first and the kept blocks k after them; then
//   A = H_kk - H_km H_mm^+ H_mk,   b = g_k - H_km H_mm^+ g_m                                 (Schur complement)
// and with A = V S V^T (eigenvalues below eps * max dropped) the prior on the kept blocks is
//   r = sqrt(S)^+ V^T b + sqrt(S) V^T dx,   dx_k = Minus(x_k, x_lin_k),
// which has gradient b and Hessian A at dx = 0. Both eigen-decompositions (H_mm for its pseudo-inverse, and A) are
// of the Jacobi-scaled matrix D M D, D = diag(M)^-1/2, so that the rank cut does not depend on units (information
// spans ~1e10 for a bias random walk to ~1e1 for a weakly seen velocity in one window; a coordinate whose diagonal
// is at rounding level, <= n u max diag, is left out); then A = D^+ V S V^T D^+ and L = sqrt(S) V^T D^+,
// offset = sqrt(S)^+ V^T D b, which still satisfy L^T L = A and L^T offset = b.
// The caller hands over exactly the residual blocks it then removes from the problem (in VINS-Mono: those touching
// the dropped frame or its features, and the previous prior); a residual on kept blocks only is folded into the
// prior as it is. Backend-internal header (ceres headers).
#include <ceres/cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace drover::backend {

// One parameter block as the marginaliser sees it. manifold == nullptr: Euclidean (tangent size = ambient size).
struct MarginalBlock {
  double* data = nullptr;
  int ambient = 0;
  const ceres::Manifold* manifold = nullptr;  // not owned
};

// The prior a marginalisation leaves on the kept blocks.
struct MarginalResult {
  bool ok = false;
  std::string reason;                               // why not ok: a failed evaluation, non-finite values, nothing kept
  std::vector<double*> kept;                        // kept block addresses, in declaration order
  std::vector<int> ambient_sizes, tangent_sizes;    // per kept block
  std::vector<const ceres::Manifold*> manifolds;    // per kept block (nullptr = Euclidean; not owned)
  std::vector<std::vector<double>> linearization;   // each kept block's value at marginalisation time (ambient)
  Eigen::MatrixXd sqrt_information;                 // L, rank x (sum of tangent sizes), L^T L = A
  Eigen::VectorXd offset;                           // rank; L^T offset = b
  int rank = 0;                                     // eigenvalues of A kept
};

class SchurMarginalizer {
 public:
  // relative_eigen_threshold: eigenvalues of the Jacobi-scaled H_mm and A below this times their largest are treated
  // as zero (VINS-Mono uses 1e-8, absolute and unscaled). Must be in [0, 1) (std::invalid_argument otherwise).
  explicit SchurMarginalizer(double relative_eigen_threshold = 1e-8);

  // Declares a parameter block (ambient size, manifold; manifold not owned, must outlive marginalize() and the
  // prior factor built from its result). Declaring the same address again with the same size and manifold is a
  // no-op; with a different one, a null pointer, a size < 1 or a manifold of another ambient size it throws
  // std::invalid_argument.
  void addBlock(double* data, int ambient_size, const ceres::Manifold* manifold);

  // A residual block: cost (not owned, must outlive marginalize()), loss (not owned, nullptr = none), its blocks in
  // the cost's order. Throws std::invalid_argument when cost is null, a block is undeclared, repeated, or its size
  // disagrees with the cost's parameter_block_sizes().
  void addResidual(const ceres::CostFunction* cost, const ceres::LossFunction* loss, std::vector<double*> blocks);

  // Schur-complements `drop` out (see the header comment) and returns the prior over the kept blocks that some
  // residual touches. Deterministic (single thread, declaration order). Throws std::invalid_argument when `drop`
  // names an undeclared block; a failed or non-finite evaluation or nothing kept gives ok = false with a reason.
  MarginalResult marginalize(const std::set<const double*>& drop) const;

  const std::vector<MarginalBlock>& blocks() const { return blocks_; }

 private:
  struct Residual {
    const ceres::CostFunction* cost;
    const ceres::LossFunction* loss;
    std::vector<int> blocks;  // indices into blocks_
  };
  double eps_;
  std::vector<MarginalBlock> blocks_;
  std::map<const double*, int> index_;
  std::vector<Residual> residuals_;
};

// The prior r = offset + L [Minus(x_1, x_lin_1); ...] over the kept blocks (rank residuals, one parameter block per
// kept block, ambient sizes). Its ambient Jacobian of block k is L_k T_k MinusJacobian(x_k) with
// T_k = d Minus(Plus(x_k, d), x_lin_k) / d d at d = 0 (identity for Euclidean blocks, J_r^-1(dtheta) for
// RightQuaternionManifold, central differences for any other manifold), so Ceres' tangent Jacobian
// (ambient * PlusJacobian) is exact away from the linearisation point too.
class MarginalPriorFactor final : public ceres::CostFunction {
 public:
  // Throws std::invalid_argument when !result.ok or its sizes disagree.
  explicit MarginalPriorFactor(MarginalResult result);
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  // Where to attach it: problem.AddResidualBlock(f, nullptr, f->blocks()).
  const std::vector<double*>& blocks() const { return result_.kept; }
  const MarginalResult& result() const { return result_; }

 private:
  MarginalResult result_;
  std::vector<int> tangent_offset_;  // column of each kept block in sqrt_information
};

}  // namespace drover::backend
