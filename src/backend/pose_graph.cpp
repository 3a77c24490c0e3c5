#include "backend/pose_graph.hpp"

#include <ceres/ceres.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "backend/pose_factors.hpp"
#include "backend/pose_graph_merge.hpp"
#include "backend/quaternion_manifold.hpp"

namespace drover::backend {

namespace {

// Parameter blocks of one node: p_world [m] and q_world_node in Eigen's (x, y, z, w) order.
struct NodeBlock {
  double p[3] = {0, 0, 0};
  double q[4] = {0, 0, 0, 1};
  bool fixed = false;

  void set(const Eigen::Isometry3d& T) {
    Eigen::Map<Eigen::Vector3d>{p} = T.translation();
    Eigen::Map<Eigen::Quaterniond>{q} = Eigen::Quaterniond(T.linear()).normalized();
  }
  Eigen::Isometry3d get() const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = Eigen::Map<const Eigen::Quaterniond>(q).normalized().toRotationMatrix();
    T.translation() = Eigen::Map<const Eigen::Vector3d>(p);
    return T;
  }
};

struct EdgeEntry {
  PoseGraphEdge edge;
  Matrix6d sqrt_information;
  ceres::ResidualBlockId block = nullptr;  // null while disabled
};

std::string idText(int id) { return std::to_string(id); }

// A rigid transform: finite, with a rotation (R^T R = I to 1e-6, det > 0) that survives the quaternion round
// trip. `what` names the value in the message.
void checkPose(const Eigen::Isometry3d& T, const std::string& what) {
  if (!T.matrix().allFinite()) throw std::invalid_argument(what + " is not finite");
  const Eigen::Matrix3d R = T.linear();
  const double orthogonality = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-6 || R.determinant() <= 0)
    throw std::invalid_argument(what + " has no rotation (|R^T R - I| = " + std::to_string(orthogonality) +
                                ", det = " + std::to_string(R.determinant()) + ")");
}

// L with L^T L = information for a symmetric positive semi-definite information (eigen-decomposition, so a
// singular information -- a direction without measurement -- is allowed).
Matrix6d sqrtInformation(const Matrix6d& information, const std::string& what) {
  if (!information.allFinite()) throw std::invalid_argument(what + ": information is not finite");
  const double scale = information.cwiseAbs().maxCoeff();
  if (scale == 0) throw std::invalid_argument(what + ": information is zero");
  const double asymmetry = (information - information.transpose()).cwiseAbs().maxCoeff();
  if (asymmetry > 1e-9 * scale)
    throw std::invalid_argument(what + ": information is not symmetric (max |I - I^T| = " +
                                std::to_string(asymmetry) + ")");
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(0.5 * (information + information.transpose()));
  const Eigen::Matrix<double, 6, 1> lambda = eig.eigenvalues();
  if (lambda.minCoeff() < -1e-9 * lambda.cwiseAbs().maxCoeff())
    throw std::invalid_argument(what + ": information is not positive semi-definite (eigenvalue " +
                                std::to_string(lambda.minCoeff()) + ")");
  return lambda.cwiseMax(0.0).cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
}

std::unique_ptr<ceres::LossFunction> makeLoss(const PoseGraphConfig& config) {
  switch (config.loop_loss) {
    case RobustLoss::kNone: return nullptr;
    case RobustLoss::kHuber: return std::make_unique<ceres::HuberLoss>(config.loop_loss_scale);
    case RobustLoss::kCauchy: return std::make_unique<ceres::CauchyLoss>(config.loop_loss_scale);
  }
  return nullptr;
}

ceres::Problem::Options problemOptions() {
  ceres::Problem::Options options;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;       // one manifold for every rotation block
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // one loss for every loop edge
  options.enable_fast_removal = true;                              // setEdgeEnabled(false) in O(1)
  return options;
}

// Sparse Cholesky on the normal equations: a pose graph's Hessian is as sparse as the graph (6x6 blocks per
// edge), and SuiteSparse's CHOLMOD with AMD ordering is the fastest factorisation Ceres has for it.
void setLinearSolver(const PoseGraphConfig& config, ceres::Solver::Options& options) {
  options.linear_solver_type = ceres::DENSE_QR;
  if (config.solver != PoseGraphLinearSolver::kSparseCholesky) return;
  for (const auto library : {ceres::SUITE_SPARSE, ceres::EIGEN_SPARSE, ceres::CX_SPARSE}) {
    if (ceres::IsSparseLinearAlgebraLibraryTypeAvailable(library)) {
      options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
      options.sparse_linear_algebra_library_type = library;
      return;
    }
  }
}

}  // namespace

struct PoseGraph::Impl {
  Config config;
  RightQuaternionManifold manifold;
  WorldYawManifold yaw_manifold;
  std::unique_ptr<ceres::LossFunction> loop_loss;
  std::map<int, NodeBlock> nodes;  // std::map: block addresses stay put as nodes are added
  std::map<std::size_t, EdgeEntry> edges;  // by index; a map so that merged edges can leave
  std::size_t next_edge = 0;
  std::size_t enabled_edges = 0;
  ceres::Problem problem;  // declared last: destroyed before the manifold and the loss it points to

  explicit Impl(const Config& c) : config(c), loop_loss(makeLoss(c)), problem(problemOptions()) {}

  bool allFinite() const {
    for (const auto& [id, n] : nodes)
      for (double v : {n.p[0], n.p[1], n.p[2], n.q[0], n.q[1], n.q[2], n.q[3]})
        if (!std::isfinite(v)) return false;
    return true;
  }

  NodeBlock& node(int id, const char* who) {
    const auto it = nodes.find(id);
    if (it == nodes.end()) throw std::invalid_argument(std::string(who) + ": unknown node id " + idText(id));
    return it->second;
  }
  EdgeEntry& edgeAt(std::size_t index) {
    const auto it = edges.find(index);
    if (it == edges.end())
      throw std::invalid_argument("PoseGraph: edge index " + std::to_string(index) + " out of range (no such edge; " +
                                  std::to_string(edges.size()) + " edges)");
    return it->second;
  }
  void removeResidual(EdgeEntry& e) {
    if (!e.block) return;
    problem.RemoveResidualBlock(e.block);  // deletes the factor; re-enabling makes a new one
    e.block = nullptr;
    --enabled_edges;
  }
  void addResidual(EdgeEntry& e) {
    const PoseGraphEdge& d = e.edge;
    NodeBlock& a = nodes.at(d.from);
    if (d.kind == EdgeKind::kPrior) {
      e.block = problem.AddResidualBlock(new PosePriorFactor(d.T_from_to_measured, e.sqrt_information), nullptr,
                                         a.p, a.q);
    } else {
      NodeBlock& b = nodes.at(d.to);
      ceres::LossFunction* loss = d.kind == EdgeKind::kLoop ? loop_loss.get() : nullptr;
      e.block = problem.AddResidualBlock(new RelativePoseFactor(d.T_from_to_measured, e.sqrt_information), loss,
                                         a.p, a.q, b.p, b.q);
    }
    ++enabled_edges;
  }
  std::size_t add(PoseGraphEdge edge, const std::string& what) {
    checkPose(edge.T_from_to_measured, what + ": measurement");
    EdgeEntry entry{edge, sqrtInformation(edge.information, what), nullptr};
    const std::size_t index = next_edge++;
    EdgeEntry& stored = edges.emplace(index, std::move(entry)).first->second;
    if (stored.edge.enabled) addResidual(stored);
    return index;
  }
  // An enabled edge of the same kind, from and to as `e`, if any.
  EdgeEntry* parallelTo(const PoseGraphEdge& e) {
    for (auto& [index, other] : edges)
      if (other.edge.enabled && other.edge.kind == e.kind && other.edge.from == e.from && other.edge.to == e.to)
        return &other;
    return nullptr;
  }
  void replace(EdgeEntry& entry, const PoseGraphEdge& edge, const std::string& what) {
    removeResidual(entry);
    entry.edge = edge;
    entry.sqrt_information = sqrtInformation(edge.information, what);
    addResidual(entry);
  }
};

PoseGraph::PoseGraph(const Config& config) {
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("PoseGraphConfig: " + why);
  impl_ = std::make_unique<Impl>(config);
}

PoseGraph::~PoseGraph() = default;
PoseGraph::PoseGraph(PoseGraph&&) noexcept = default;
PoseGraph& PoseGraph::operator=(PoseGraph&&) noexcept = default;

void PoseGraph::addNode(int id, const Eigen::Isometry3d& T_world_node) {
  if (hasNode(id)) throw std::invalid_argument("PoseGraph::addNode: duplicate node id " + idText(id));
  checkPose(T_world_node, "PoseGraph::addNode: pose of node " + idText(id));
  const bool first = impl_->nodes.empty();
  NodeBlock& n = impl_->nodes[id];
  n.set(T_world_node);
  impl_->problem.AddParameterBlock(n.p, 3);
  ceres::Manifold* rotation = impl_->config.yaw_only_rotation ? static_cast<ceres::Manifold*>(&impl_->yaw_manifold)
                                                               : static_cast<ceres::Manifold*>(&impl_->manifold);
  impl_->problem.AddParameterBlock(n.q, 4, rotation);
  if (first) setFixed(id, true);  // the gauge: a pose graph only determines poses up to one rigid motion
}

void PoseGraph::setPose(int id, const Eigen::Isometry3d& T_world_node) {
  NodeBlock& n = impl_->node(id, "PoseGraph::setPose");
  checkPose(T_world_node, "PoseGraph::setPose: pose of node " + idText(id));
  n.set(T_world_node);
}

Eigen::Isometry3d PoseGraph::pose(int id) const { return impl_->node(id, "PoseGraph::pose").get(); }

bool PoseGraph::hasNode(int id) const { return impl_->nodes.count(id) != 0; }

void PoseGraph::setFixed(int id, bool fixed) {
  NodeBlock& n = impl_->node(id, "PoseGraph::setFixed");
  n.fixed = fixed;
  for (double* block : {n.p, n.q}) {
    if (fixed) {
      impl_->problem.SetParameterBlockConstant(block);
    } else {
      impl_->problem.SetParameterBlockVariable(block);
    }
  }
}

bool PoseGraph::isFixed(int id) const { return impl_->node(id, "PoseGraph::isFixed").fixed; }

std::size_t PoseGraph::size() const { return impl_->nodes.size(); }

std::vector<int> PoseGraph::nodeIds() const {
  std::vector<int> ids;
  ids.reserve(impl_->nodes.size());
  for (const auto& [id, node] : impl_->nodes) ids.push_back(id);
  return ids;
}

std::size_t PoseGraph::addEdge(int from, int to, const Eigen::Isometry3d& T_from_to_measured,
                               const Matrix6d& information, EdgeKind kind) {
  const std::string what = "PoseGraph::addEdge " + idText(from) + " -> " + idText(to);
  if (kind == EdgeKind::kPrior) throw std::invalid_argument(what + ": a prior is added with addPrior()");
  const bool from_known = hasNode(from), to_known = hasNode(to);
  if (!from_known && !to_known && from != to)
    throw std::invalid_argument(what + ": unknown node ids " + idText(from) + " and " + idText(to));
  if (!from_known || !to_known)
    throw std::invalid_argument(what + ": unknown node id " + idText(from_known ? to : from));
  if (from == to) throw std::invalid_argument(what + ": an edge must join two different nodes");
  return impl_->add(PoseGraphEdge{from, to, T_from_to_measured, information, kind, true}, what);
}

std::size_t PoseGraph::addPrior(int id, const Eigen::Isometry3d& T_world_node_measured, const Matrix6d& information) {
  const std::string what = "PoseGraph::addPrior on node " + idText(id);
  if (!hasNode(id)) throw std::invalid_argument(what + ": unknown node id " + idText(id));
  return impl_->add(PoseGraphEdge{id, id, T_world_node_measured, information, EdgeKind::kPrior, true}, what);
}

void PoseGraph::mergeNode(int id, int into) {
  const std::string what = "PoseGraph::mergeNode " + idText(id) + " into " + idText(into);
  if (id == into) throw std::invalid_argument(what + ": a node cannot be merged into itself");
  NodeBlock& gone = impl_->node(id, "PoseGraph::mergeNode");
  impl_->node(into, "PoseGraph::mergeNode");
  const Eigen::Isometry3d T_id_into = gone.get().inverse() * pose(into);
  std::vector<PoseGraphEdge> moved;
  for (auto it = impl_->edges.begin(); it != impl_->edges.end();) {
    EdgeEntry& e = it->second;
    if (e.edge.from != id && e.edge.to != id) {
      ++it;
      continue;
    }
    const PoseGraphEdge& d = e.edge;
    const bool between = d.from == into || d.to == into;  // now inside one rigid body: no information left
    if (d.enabled && !between)
      moved.push_back(d.from == id && d.kind != EdgeKind::kPrior ? moveFromEnd(d, into, T_id_into)
                                                                  : moveToEnd(d, into, T_id_into));
    impl_->removeResidual(e);
    it = impl_->edges.erase(it);
  }
  for (const PoseGraphEdge& m : moved) {
    if (EdgeEntry* parallel = impl_->parallelTo(m)) {
      impl_->replace(*parallel, fuseParallel(parallel->edge, m), what);
    } else {
      impl_->add(m, what);
    }
  }
  if (gone.fixed) setFixed(into, true);
  impl_->problem.RemoveParameterBlock(gone.p);
  impl_->problem.RemoveParameterBlock(gone.q);
  impl_->nodes.erase(id);
}

std::size_t PoseGraph::edgeCount() const { return impl_->edges.size(); }

std::vector<std::size_t> PoseGraph::edgeIndices() const {
  std::vector<std::size_t> out;
  out.reserve(impl_->edges.size());
  for (const auto& [index, e] : impl_->edges) out.push_back(index);
  return out;
}
std::size_t PoseGraph::enabledEdgeCount() const { return impl_->enabled_edges; }

const PoseGraphEdge& PoseGraph::edge(std::size_t index) const { return impl_->edgeAt(index).edge; }

void PoseGraph::setEdgeEnabled(std::size_t index, bool enabled) {
  EdgeEntry& e = impl_->edgeAt(index);
  if (e.edge.enabled == enabled) return;
  e.edge.enabled = enabled;
  if (enabled) {
    impl_->addResidual(e);
  } else {
    impl_->removeResidual(e);
  }
}

double PoseGraph::cost() const {
  if (impl_->enabled_edges == 0) return 0.0;
  double cost = 0;
  impl_->problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  return cost;
}

PoseGraphResult PoseGraph::optimize() {
  PoseGraphResult result;
  result.nodes = static_cast<int>(size());
  result.edges = static_cast<int>(impl_->enabled_edges);
  ceres::Solver::Options options;
  setLinearSolver(impl_->config, options);
  result.linear_solver = std::string(ceres::LinearSolverTypeToString(options.linear_solver_type));
  if (options.linear_solver_type == ceres::SPARSE_NORMAL_CHOLESKY)
    result.linear_solver +=
        std::string(" (") + ceres::SparseLinearAlgebraLibraryTypeToString(options.sparse_linear_algebra_library_type) +
        ")";
  if (impl_->enabled_edges == 0) {
    result.converged = result.usable = true;
    result.reason = "no enabled edges: nothing to optimise";
    return result;
  }
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.max_num_iterations = impl_->config.max_iterations;
  options.initial_trust_region_radius = impl_->config.initial_trust_region_radius;
  options.function_tolerance = impl_->config.function_tolerance;
  options.gradient_tolerance = impl_->config.gradient_tolerance;
  options.parameter_tolerance = impl_->config.parameter_tolerance;
  options.num_threads = impl_->config.threads;
  options.logging_type = ceres::SILENT;

  const std::map<int, NodeBlock> before = impl_->nodes;  // restored on failure
  const auto start = std::chrono::steady_clock::now();
  ceres::Solver::Summary summary;
  ceres::Solve(options, &impl_->problem, &summary);
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.usable = summary.IsSolutionUsable();
  result.reason = summary.message;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  // A solve Ceres calls usable can still leave a non-finite pose (seen once, live, after ~800 loops of an hour on
  // the farm course): every later solve then fails and a correction would carry NaN. Refused and rolled back.
  if (result.usable && !impl_->allFinite()) {
    result.usable = result.converged = false;
    result.reason = "non-finite solution (" + summary.message + ")";
  }
  if (!result.usable) {
    for (auto& [id, node] : impl_->nodes) {
      const NodeBlock& old = before.at(id);
      std::copy(old.p, old.p + 3, node.p);
      std::copy(old.q, old.q + 4, node.q);
    }
    result.final_cost = result.initial_cost;
  }
  return result;
}

const PoseGraphConfig& PoseGraph::config() const { return impl_->config; }

}  // namespace drover::backend
