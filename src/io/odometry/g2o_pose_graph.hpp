#pragma once
// g2o pose graphs (io/g2o_io.hpp) <-> backend::PoseGraph. Lives in drover_io_odometry, the one piece of io/
// that may see the odometry modules: drover_io depends on the core only (its readers and tests build without
// Ceres), and the backend does no IO, so the glue between the two cannot live in either.
//
// Information. g2o's EDGE_SE3:QUAT error is e = [R_m^T (t_ij - t_m); qv(R_m^T R_ij)] (the translation and the
// vector part of the unit quaternion, w >= 0, of the error transform Z^-1 T_i^-1 T_j), whereas Drover's
// RelativePoseFactor uses r = [t_ij - t_m; Log(R_m^T R_ij)], t_ij = R_i^T (p_j - p_i). Since qv = sin(|phi|/2)
// phi/|phi| = phi/2 + O(|phi|^3), e = S r with S = diag(R_m^T, I/2) to first order (exactly in the
// translation), so the information of r is S^T Info_g2o S: the rotation block is divided by 4, the
// translation-rotation blocks by 2 (and rotated by R_m; a no-op for isotropic translation information, as in
// the benchmark graphs). With this, e^T Info_g2o e = r^T Info r up to O(|phi|^4), i.e. the Ceres cost
// 0.5 sum |r|^2 is half of g2o's chi2 -- the figures `drover graph optimize` prints are Ceres costs.
//
// Edge kinds: g2o has none. An edge between consecutive ids (|id2 - id1| == 1) is odometry, every other edge a
// loop closure (which gets PoseGraphConfig::loop_loss), as in the benchmark graphs built from odometry chains.
#include <Eigen/Core>
#include <string>

#include "backend/pose_graph.hpp"
#include "io/g2o_io.hpp"

namespace drover::io {

// Information of Drover's [dp; dphi] from g2o's [t; qv] information, and back, for the measured rotation R_m.
backend::Matrix6d informationFromG2o(const backend::Matrix6d& information_g2o, const Eigen::Matrix3d& R_m);
backend::Matrix6d informationToG2o(const backend::Matrix6d& information, const Eigen::Matrix3d& R_m);

// Vertices in file order (so the first vertex is the default gauge), edges with the kinds above; FIX lines,
// when there are any, replace the default gauge. Errors the graph raises become IoError naming `file` and
// the vertex's or edge's line.
backend::PoseGraph toPoseGraph(const G2oGraph& g2o, const backend::PoseGraphConfig& config = {},
                               const std::string& file = "g2o graph");

// Every node (ascending id), FIX for fixed nodes and every enabled relative edge. Throws std::invalid_argument
// for an enabled prior edge, which EDGE_SE3:QUAT cannot express.
G2oGraph toG2o(const backend::PoseGraph& graph);

// Replaces the vertex poses by the graph's (after optimize()), keeping the edges exactly as read.
// Throws std::invalid_argument when a vertex is not in the graph.
void updateVertexPoses(G2oGraph& g2o, const backend::PoseGraph& graph);

}  // namespace drover::io
