#pragma once
// SE(3) pose graph on Ceres: nodes are poses T_world_node (keyframes), edges relative-pose measurements
// T_from_to between two nodes (odometry, loop closures) or absolute priors on one node. The factor is the
// backend's RelativePoseFactor (backend/pose_factors.hpp):
//   r = L [R_from^T (p_to - p_from) - t_m; Log(R_m^T R_from^T R_to)],   L^T L = information,
// i.e. the error is [translation (3) [m], in the `from` frame; rotation (3) [rad], right perturbation] -- the
// ordering of the scan matcher's 6x6 and of g2o's EDGE_SE3:QUAT (whose rotation block needs a scale, see
// io/odometry/g2o_pose_graph.hpp). Rotations are unit quaternions on RightQuaternionManifold
// (R -> R Exp(dtheta), backend/quaternion_manifold.hpp). Loop edges take a robust loss (Huber or Cauchy,
// in whitened units), the rest are plain least squares. Cost = Ceres' 0.5 sum_k rho(|r_k|^2).
//
// Incremental use (loop closure, as LIO-SAM re-solves its keyframe graph after each loop): the Ceres problem
// lives as long as the graph; addNode/addEdge/setEdgeEnabled only add or remove residual blocks, and
// optimize() starts from the current poses (warm start) and writes the solution back in place.
// This header is free of Ceres (pimpl), so the pipeline includes it cheaply. Not thread-safe.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace drover::backend {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

enum class EdgeKind {
  kOdometry,  // between consecutive keyframes; plain least squares
  kLoop,      // loop closure; gets PoseGraphConfig::loop_loss
  kPrior,     // absolute pose of one node (from == to; the measurement is T_world_node); plain least squares
};

enum class RobustLoss { kNone, kHuber, kCauchy };

enum class PoseGraphLinearSolver {
  kSparseCholesky,  // SPARSE_NORMAL_CHOLESKY on SuiteSparse, else Eigen's sparse Cholesky when Ceres lacks it
  kDenseQr,         // DENSE_QR: tiny graphs only (cost grows with the cube of the node count)
};

struct PoseGraphConfig {
  int max_iterations = 100;  // Levenberg-Marquardt iterations per optimize(), >= 1
  PoseGraphLinearSolver solver = PoseGraphLinearSolver::kSparseCholesky;
  // Ceres' initial trust-region radius (the inverse of LM's initial damping). Pose graphs start from chained
  // odometry or from the previous solution, close enough that the first steps are best taken as Gauss-Newton:
  // on parking-garage.g2o 1e10 converges in 5 iterations to cost 0.6193453, Ceres' default 1e4 stops after 13
  // at 0.6194832 (function tolerance met while still creeping). A failed step shrinks the radius as usual.
  double initial_trust_region_radius = 1e10;  // [-], > 0
  // Ceres' convergence tests: |delta cost| / cost < function_tolerance, or the max-norm of the projected
  // gradient < gradient_tolerance, or |delta x| < parameter_tolerance (|x| + parameter_tolerance).
  double function_tolerance = 1e-6;   // [-], > 0
  double gradient_tolerance = 1e-10;  // [cost units / parameter units], > 0
  double parameter_tolerance = 1e-8;  // [-], > 0
  // Loss on loop edges: rho(s) with s = |r|^2 the squared whitened residual. Huber is quadratic up to
  // |r| = loop_loss_scale and linear beyond; Cauchy s -> a^2 log(1 + s / a^2). The default 3 keeps inliers of a
  // 6-DoF edge (E|r|^2 = 6, |r| ~ 2.4) quadratic.
  RobustLoss loop_loss = RobustLoss::kHuber;
  double loop_loss_scale = 3.0;  // [whitened residual units, i.e. sigmas], > 0
  int threads = 1;               // Ceres threads (Jacobian evaluation, linear solver), >= 1
  // Nodes turn only about the world z axis (backend::WorldYawManifold: x, y, z and yaw are corrected, roll and pitch
  // stay as given). For graphs in a gravity-aligned world whose odometry's tilt comes from an IMU (VINS-Mono's
  // 4-DoF pose graph); a loop's relative roll and pitch then cannot tilt the map away from gravity.
  bool yaw_only_rotation = false;
  // Empty when valid: max_iterations >= 1, tolerances, initial_trust_region_radius and loop_loss_scale finite
  // and > 0, threads >= 1.
  std::string validate() const;
};

// "none", "huber", "cauchy" <-> RobustLoss; parse throws std::invalid_argument naming the text.
RobustLoss parseRobustLoss(const std::string& name);
std::string robustLossName(RobustLoss loss);

struct PoseGraphResult {
  bool converged = false;  // a Ceres convergence test was met
  bool usable = false;     // the poses were updated (converged, or stopped at max_iterations while improving)
  std::string reason;      // Ceres' termination message, or why nothing was solved
  double initial_cost = 0, final_cost = 0;  // Ceres cost 0.5 sum rho(|r|^2) before and after (robustified)
  int iterations = 0;      // LM iterations (successful + unsuccessful steps)
  double time_ms = 0;      // wall time of the solve, preprocessing included [ms]
  int nodes = 0;           // nodes in the graph
  int edges = 0;           // enabled edges
  std::string linear_solver;  // what was used, e.g. "SPARSE_NORMAL_CHOLESKY (SUITE_SPARSE)"
};

// A copy of one edge as it was added.
struct PoseGraphEdge {
  int from = 0, to = 0;             // node ids (equal for kPrior)
  Eigen::Isometry3d T_from_to_measured = Eigen::Isometry3d::Identity();  // T_world_node for kPrior
  Matrix6d information = Matrix6d::Identity();  // of [dp (m); dphi (rad)]
  EdgeKind kind = EdgeKind::kOdometry;
  bool enabled = true;
};

class PoseGraph {
 public:
  using Config = PoseGraphConfig;
  // Throws std::invalid_argument when config.validate() fails.
  explicit PoseGraph(const Config& config = Config());
  ~PoseGraph();
  PoseGraph(PoseGraph&&) noexcept;
  PoseGraph& operator=(PoseGraph&&) noexcept;
  PoseGraph(const PoseGraph&) = delete;
  PoseGraph& operator=(const PoseGraph&) = delete;

  // Nodes. Ids are any ints, unique. The first node added is fixed (the gauge) until setFixed says otherwise.
  // Throws std::invalid_argument on a duplicate id or a non-finite / non-rotation pose (the rotation is
  // re-normalised through its quaternion).
  void addNode(int id, const Eigen::Isometry3d& T_world_node);
  void setPose(int id, const Eigen::Isometry3d& T_world_node);  // unknown id / non-finite -> invalid_argument
  Eigen::Isometry3d pose(int id) const;                          // unknown id -> invalid_argument
  bool hasNode(int id) const;
  void setFixed(int id, bool fixed);  // a fixed node is held constant by optimize()
  bool isFixed(int id) const;
  std::size_t size() const;           // number of nodes
  std::vector<int> nodeIds() const;   // ascending

  // Edges; return the edge's index (0, 1, ... in order of addition). `information` is the 6x6 information of
  // the error [translation; rotation] above. Throws std::invalid_argument naming unknown node ids, from == to,
  // a non-finite measurement, or an information that is not finite, symmetric (to 1e-9 relative) and positive
  // semi-definite, or is zero.
  std::size_t addEdge(int from, int to, const Eigen::Isometry3d& T_from_to_measured, const Matrix6d& information,
                      EdgeKind kind);
  std::size_t addPrior(int id, const Eigen::Isometry3d& T_world_node_measured, const Matrix6d& information);
  std::size_t edgeCount() const;         // all edges, disabled ones included
  std::size_t enabledEdgeCount() const;
  std::vector<std::size_t> edgeIndices() const;        // of every edge there is, ascending
  const PoseGraphEdge& edge(std::size_t index) const;  // no such edge (never added, or merged) -> invalid_argument
  // A disabled edge stays in the list (indices do not move) but takes no part in optimize() or cost() -- e.g. a
  // loop closure that proved wrong. Out of range -> invalid_argument.
  void setEdgeEnabled(std::size_t index, bool enabled);

  // Merges node `id` into node `into`: their relative pose, at the current estimate, is held rigid from now on
  // and `id` leaves the graph, so a graph whose places are revisited stays as large as the places (keyframe
  // retirement). Every enabled edge of `id` is re-expressed on `into` with the same error up to a linear map A
  // (exact for the `from` end, first order for the `to` end and priors) and information A^-T I A^-1; edges
  // between the two are dropped, as are `id`'s disabled edges. An edge that then parallels an enabled one of the
  // same kind, from and to, is fused into it (first order: information I1 + I2, measurement moved by
  // (I1 + I2)^-1 I2 d). A fixed `id` fixes `into` (the gauge). Re-expressed edges get new indices; the old ones
  // are gone. Throws std::invalid_argument for unknown ids or id == into.
  void mergeNode(int id, int into);

  // Cost 0.5 sum rho(|r|^2) of the enabled edges at the current poses (no solve).
  double cost() const;
  // Levenberg-Marquardt from the current poses; on success the poses are updated in place. Never throws on a
  // failed solve: the poses are restored and the result says why.
  PoseGraphResult optimize();

  const Config& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The information of our error r = [dp; dphi] from the information of a right SE(3) perturbation
// T_from_to = T_m Exp([rho; phi]) (the scan matcher's tangent): to first order dp = R_m rho and dphi = phi, so
// information = diag(R_m, I) info_rho_phi diag(R_m^T, I).
Matrix6d informationFromRightPerturbation(const Matrix6d& information_rho_phi, const Eigen::Matrix3d& R_m);

}  // namespace drover::backend
