#include "io/odometry/g2o_pose_graph.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "io/error.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {

namespace {

// e_g2o = S r to first order, S = diag(R_m^T, I/2) (see the header).
backend::Matrix6d errorMap(const Eigen::Matrix3d& R_m) {
  backend::Matrix6d S = backend::Matrix6d::Zero();
  S.topLeftCorner<3, 3>() = R_m.transpose();
  S.bottomRightCorner<3, 3>() = 0.5 * Eigen::Matrix3d::Identity();
  return S;
}

backend::Matrix6d errorMapInverse(const Eigen::Matrix3d& R_m) {
  backend::Matrix6d S_inv = backend::Matrix6d::Zero();
  S_inv.topLeftCorner<3, 3>() = R_m;
  S_inv.bottomRightCorner<3, 3>() = 2.0 * Eigen::Matrix3d::Identity();
  return S_inv;
}

bool consecutive(int a, int b) { return std::llabs(static_cast<long long>(a) - b) == 1; }

}  // namespace

backend::Matrix6d informationFromG2o(const backend::Matrix6d& information_g2o, const Eigen::Matrix3d& R_m) {
  const backend::Matrix6d S = errorMap(R_m);
  const backend::Matrix6d info = S.transpose() * information_g2o * S;
  return 0.5 * (info + info.transpose());  // exactly symmetric despite rounding
}

backend::Matrix6d informationToG2o(const backend::Matrix6d& information, const Eigen::Matrix3d& R_m) {
  const backend::Matrix6d S_inv = errorMapInverse(R_m);
  const backend::Matrix6d info = S_inv.transpose() * information * S_inv;
  return 0.5 * (info + info.transpose());
}

backend::PoseGraph toPoseGraph(const G2oGraph& g2o, const backend::PoseGraphConfig& config, const std::string& file) {
  backend::PoseGraph graph(config);
  std::size_t line = 0;
  try {
    for (const G2oVertex& v : g2o.vertices) {
      line = v.line;
      graph.addNode(v.id, v.T_world_vertex);
    }
    if (!g2o.fixed.empty() && !g2o.vertices.empty()) {
      graph.setFixed(g2o.vertices.front().id, false);
      for (const int id : g2o.fixed) graph.setFixed(id, true);
    }
    for (const G2oEdge& e : g2o.edges) {
      line = e.line;
      const backend::EdgeKind kind = consecutive(e.from, e.to) ? backend::EdgeKind::kOdometry : backend::EdgeKind::kLoop;
      graph.addEdge(e.from, e.to, e.T_from_to, informationFromG2o(e.information, e.T_from_to.linear()), kind);
    }
  } catch (const std::invalid_argument& error) {
    fail(file, line > 0 ? lineRecord(line) : "", error.what());
  }
  return graph;
}

G2oGraph toG2o(const backend::PoseGraph& graph) {
  G2oGraph g2o;
  for (const int id : graph.nodeIds()) {
    g2o.vertices.push_back(G2oVertex{id, graph.pose(id), 0});
    if (graph.isFixed(id)) g2o.fixed.push_back(id);
  }
  for (const std::size_t i : graph.edgeIndices()) {
    const backend::PoseGraphEdge& e = graph.edge(i);
    if (!e.enabled) continue;
    if (e.kind == backend::EdgeKind::kPrior)
      throw std::invalid_argument("toG2o: edge " + std::to_string(i) + " is a prior on node " + std::to_string(e.from) +
                                  ", which EDGE_SE3:QUAT cannot express");
    g2o.edges.push_back(G2oEdge{e.from, e.to, e.T_from_to_measured,
                                informationToG2o(e.information, e.T_from_to_measured.linear()), 0});
  }
  return g2o;
}

void updateVertexPoses(G2oGraph& g2o, const backend::PoseGraph& graph) {
  for (G2oVertex& v : g2o.vertices) {
    if (!graph.hasNode(v.id))
      throw std::invalid_argument("updateVertexPoses: vertex " + std::to_string(v.id) + " is not in the pose graph");
    v.T_world_vertex = graph.pose(v.id);
  }
}

}  // namespace drover::io
