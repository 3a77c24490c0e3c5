#pragma once
// Marginalisation of the oldest navigation state of a sliding window by the Schur complement (Sibley, Matthies,
// Sukhatme, "Sliding window filter with application to planetary landing", JFR 2010; the same construction as
// VINS-Mono's MarginalizationFactor). The factors that touch the dropped state x_m -- its prior, its pose
// measurement, the IMU and bias factors to the next state x_r -- are linearised at the current estimate in the
// 30-dimensional tangent space [x_m; x_r] (each x = [dp, dtheta, dv, db], 15), giving H = J^T J and g = J^T r;
// then
//   A = H_rr - H_rm H_mm^+ H_mr,   b = g_r - H_rm H_mm^+ g_m                                   (Schur complement)
// and with A = V S V^T the prior on x_r is  r = sqrt(S)^+ V^T b + sqrt(S) V^T dx_r  (NavStatePriorFactor), which
// has the same gradient b and Hessian A. Backend-internal header.
#include <ceres/cost_function.h>

#include <array>
#include <string>
#include <vector>

#include "backend/state_prior_factor.hpp"

namespace drover::backend {

// One factor touching the dropped state. `blocks` index the 8 parameter blocks of marginalizeState():
// 0..3 = p, q, v, bias of the dropped state, 4..7 = p, q, v, bias of the kept state, in the cost's block order.
struct MarginalizationTerm {
  const ceres::CostFunction* cost = nullptr;
  std::vector<int> blocks;
};

struct MarginalPrior {
  bool ok = false;
  std::string reason;         // why not ok (a failed evaluation, non-finite values)
  int rank = 0;               // rank of the Schur complement kept (<= 15)
  StatePoint linearization;   // the kept state's estimate the prior is linear around
  Matrix15d sqrt_information = Matrix15d::Zero();
  Vector15d offset = Vector15d::Zero();
};

// Blocks hold the current estimate: dropped = {p, q, v, bias} of x_m, kept = {p, q, v, bias} of x_r.
MarginalPrior marginalizeState(const std::vector<MarginalizationTerm>& terms, const std::array<double*, 4>& dropped,
                               const std::array<double*, 4>& kept);

}  // namespace drover::backend
