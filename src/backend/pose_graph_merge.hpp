#pragma once
// The edge algebra behind PoseGraph::mergeNode: moving one end of a pose-graph edge onto another node rigidly
// attached to it, and fusing two parallel edges. Errors as in pose_graph.hpp: for an edge from a to b with
// measurement T_m = (R_m, t_m) and X = T_a^-1 T_b, r = [t_X - t_m; Log(R_m^T R_X)] (translation [m] in a's frame,
// rotation [rad], right perturbation); for a prior on a, r = [p_a - p_m; Log(R_m^T R_a)].
#include "backend/pose_graph.hpp"

namespace drover::backend {

// Edge `e` whose `from` node is replaced by `into`, with T_from_into (the old from node to `into`) held rigid:
// the new measurement is T_into_from T_m and the new error is exactly diag(R^T, I) times the old (R the rotation
// of T_from_into), so the information becomes diag(R^T, I) I diag(R, I).
PoseGraphEdge moveFromEnd(const PoseGraphEdge& e, int into, const Eigen::Isometry3d& T_from_into);

// Edge (or prior) `e` whose `to` node (for a prior: its node) is replaced by `into`, with T_to_into = (R_x, t_x)
// held rigid: the new measurement is T_m T_to_into and, to first order in the error, r' = A r with
// A = [I, -R_m [t_x]x; 0, R_x^T], so the information becomes A^-T I A^-1.
PoseGraphEdge moveToEnd(const PoseGraphEdge& e, int into, const Eigen::Isometry3d& T_to_into);

// One edge for two measurements of the same relative pose (same from, to and kind): the minimiser of the two
// errors' sum, to first order about a's measurement: d = [t_b - t_a; Log(R_a^T R_b)], delta = (I_a + I_b)^-1 I_b d,
// measurement (R_a Exp(delta_phi), t_a + delta_t), information I_a + I_b. Throws std::invalid_argument when the
// two do not join the same nodes in the same direction or differ in kind.
PoseGraphEdge fuseParallel(const PoseGraphEdge& a, const PoseGraphEdge& b);

}  // namespace drover::backend
