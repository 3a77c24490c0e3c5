// PoseGraph::mergeNode and its edge algebra (backend/pose_graph_merge.hpp) against direct evaluation of the edge
// errors and against the unmerged graph's solution: a second pass over a helix merged into the first.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <vector>

#include "backend/pose_graph.hpp"
#include "backend/pose_graph_merge.hpp"
#include "geometry/se3.hpp"
#include "geometry/so3.hpp"
#include "pose_graph_test_util.hpp"

namespace drover::backend {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using geometry::expSE3;

using test::randomTangent;

Eigen::Isometry3d randomPose(std::mt19937& rng) { return expSE3(randomTangent(rng, 5.0, 1.0)); }

// A random symmetric positive definite information with sigmas of centimetres and milliradians, correlated.
Matrix6d randomInformation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d L = Matrix6d::Zero();
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j <= i; ++j) L(i, j) = i == j ? 3.0 + std::abs(n(rng)) : 0.5 * n(rng);
  Vector6d scale;
  scale << 50, 50, 50, 500, 500, 500;  // 1 / (2 cm), 1 / (2 mrad)
  const Matrix6d S = scale.asDiagonal() * L;
  return S * S.transpose();
}

// The edge's error at the given node poses, as pose_graph.hpp defines it (T_from ignored for a prior).
Vector6d error(const PoseGraphEdge& e, const Eigen::Isometry3d& T_from, const Eigen::Isometry3d& T_to) {
  const Eigen::Isometry3d X = e.kind == EdgeKind::kPrior ? T_to : T_from.inverse() * T_to;
  Vector6d r;
  r.head<3>() = X.translation() - e.T_from_to_measured.translation();
  r.tail<3>() = geometry::logSO3(e.T_from_to_measured.linear().transpose() * X.linear());
  return r;
}

double cost(const PoseGraphEdge& e, const Eigen::Isometry3d& T_from, const Eigen::Isometry3d& T_to) {
  const Vector6d r = error(e, T_from, T_to);
  return r.dot(e.information * r);
}

TEST(PoseGraphMerge, MovingTheFromEndOfAnEdgeOntoARigidlyAttachedNodeKeepsItsCostExactly) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Isometry3d T_id = randomPose(rng), T_to = randomPose(rng), T_id_into = randomPose(rng);
    // Measured far from the truth (0.3 m, 0.2 rad): the identity holds at any residual.
    const PoseGraphEdge e{1, 2, T_id.inverse() * T_to * expSE3(randomTangent(rng, 0.3, 0.2)), randomInformation(rng),
                          EdgeKind::kOdometry, true};
    const PoseGraphEdge moved = moveFromEnd(e, 7, T_id_into);
    EXPECT_EQ(moved.from, 7);
    EXPECT_EQ(moved.to, 2);
    const double c = cost(e, T_id, T_to);
    EXPECT_NEAR(cost(moved, T_id * T_id_into, T_to), c, 1e-9 * c);
  }
}

TEST(PoseGraphMerge, MovingTheToEndOfAnEdgeOrAPriorKeepsItsCostToFirstOrderInTheResidual) {
  std::mt19937 rng(6);
  for (const EdgeKind kind : {EdgeKind::kLoop, EdgeKind::kPrior}) {
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::Isometry3d T_from = randomPose(rng), T_id = randomPose(rng);
      const Eigen::Isometry3d T_id_into = expSE3(randomTangent(rng, 1.0, 0.5));  // a neighbour a metre away
      const Eigen::Isometry3d truth = kind == EdgeKind::kPrior ? T_id : T_from.inverse() * T_id;
      const int from = kind == EdgeKind::kPrior ? 2 : 1;
      // A residual of a centimetre and 10 mrad: the neglected term is |r_phi| |t_x| ~ 1 % of |r|.
      const PoseGraphEdge e{from, 2, truth * expSE3(randomTangent(rng, 0.01, 0.01)), randomInformation(rng), kind,
                            true};
      const PoseGraphEdge moved = moveToEnd(e, 7, T_id_into);
      EXPECT_EQ(moved.to, 7);
      EXPECT_EQ(moved.from, kind == EdgeKind::kPrior ? 7 : 1);
      const double c = cost(e, T_from, T_id);
      EXPECT_NEAR(cost(moved, T_from, T_id * T_id_into), c, 0.05 * c) << "trial " << trial;
    }
  }
}

TEST(PoseGraphMerge, FusingTwoParallelEdgesGivesTheMinimiserOfTheirSumAndTheSumOfTheirInformation) {
  std::mt19937 rng(7);
  const Eigen::Isometry3d truth = randomPose(rng);
  // Odometry edges: plain least squares (a loop edge's Huber loss would make the sum's minimiser another one).
  const PoseGraphEdge a{0, 1, truth * expSE3(randomTangent(rng, 0.02, 0.01)), randomInformation(rng),
                        EdgeKind::kOdometry, true};
  const PoseGraphEdge b{0, 1, truth * expSE3(randomTangent(rng, 0.02, 0.01)), randomInformation(rng),
                        EdgeKind::kOdometry, true};
  PoseGraphConfig config;
  config.function_tolerance = config.parameter_tolerance = 1e-14;
  PoseGraph both(config), fused(config);
  for (PoseGraph* g : {&both, &fused}) {
    g->addNode(0, Eigen::Isometry3d::Identity());
    g->addNode(1, truth);
  }
  both.addEdge(0, 1, a.T_from_to_measured, a.information, a.kind);
  both.addEdge(0, 1, b.T_from_to_measured, b.information, b.kind);
  const PoseGraphEdge f = fuseParallel(a, b);
  fused.addEdge(0, 1, f.T_from_to_measured, f.information, f.kind);
  ASSERT_TRUE(both.optimize().usable);
  ASSERT_TRUE(fused.optimize().usable);
  // Exact to first order in the measurements' difference d (~3 cm, 15 mrad): what is left is of the order of
  // |d|^2, 2e-4 (measured: 2.0e-5 m, 2.7e-5 rad).
  EXPECT_LT((both.pose(1).translation() - fused.pose(1).translation()).norm(), 1e-4);
  EXPECT_LT(geometry::logSO3(both.pose(1).linear().transpose() * fused.pose(1).linear()).norm(), 1e-4);
  EXPECT_TRUE(f.information.isApprox(a.information + b.information));
  PoseGraphEdge reversed = b;
  std::swap(reversed.from, reversed.to);
  EXPECT_THROW(fuseParallel(a, reversed), std::invalid_argument);
  PoseGraphEdge loop = b;
  loop.kind = EdgeKind::kLoop;
  EXPECT_THROW(fuseParallel(a, loop), std::invalid_argument);
}

// Two passes over a 40-pose helix (radius 10 m), the second 0.3 m to the side, chained by noisy odometry (5 cm,
// 10 mrad per step) with a loop edge from every pose of the second pass to its twin in the first (1 cm, 2 mrad).
struct TwoPasses {
  static constexpr int kPass = 40;
  std::vector<Eigen::Isometry3d> truth;
  PoseGraph graph;

  explicit TwoPasses(unsigned seed) {
    std::mt19937 rng(seed);
    for (int k = 0; k < 2 * kPass; ++k) {
      const double a = 2 * M_PI * (k % kPass) / kPass;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      const double r = k < kPass ? 10.0 : 10.3;
      T.translation() << r * std::cos(a), r * std::sin(a), 0.0;
      T.linear() = geometry::expSO3(Eigen::Vector3d(0.05 * std::sin(3 * a), 0.02, a + M_PI / 2));
      truth.push_back(T);
    }
    const Matrix6d odometry = Vector6d((Vector6d() << 400, 400, 400, 1e4, 1e4, 1e4).finished()).asDiagonal();
    const Matrix6d loop = Vector6d((Vector6d() << 1e4, 1e4, 1e4, 2.5e5, 2.5e5, 2.5e5).finished()).asDiagonal();
    Eigen::Isometry3d chained = truth[0];
    graph.addNode(0, chained);
    for (int k = 1; k < 2 * kPass; ++k) {
      const Eigen::Isometry3d measured = truth[k - 1].inverse() * truth[k] * expSE3(randomTangent(rng, 0.05, 0.01));
      chained = chained * measured;
      graph.addNode(k, chained);
      graph.addEdge(k - 1, k, measured, odometry, EdgeKind::kOdometry);
    }
    for (int k = kPass; k < 2 * kPass; ++k)
      graph.addEdge(k - kPass, k, truth[k - kPass].inverse() * truth[k] * expSE3(randomTangent(rng, 0.01, 0.002)),
                    loop, EdgeKind::kLoop);
  }
};

// The largest distance between the two graphs' poses of nodes first..last, each relative to node `first` (the
// merged graph's gauge is node 40, the full one's node 0).
double positionGap(const PoseGraph& a, const PoseGraph& b, int first, int last) {
  double worst = 0;
  for (int k = first; k <= last; ++k) {
    const Eigen::Vector3d pa = (a.pose(first).inverse() * a.pose(k)).translation();
    const Eigen::Vector3d pb = (b.pose(first).inverse() * b.pose(k)).translation();
    worst = std::max(worst, (pa - pb).norm());
  }
  return worst;
}

TEST(PoseGraphMerge, ASecondPassMergedIntoTheFirstKeepsTheSolutionWithAGraphOfOnePass) {
  TwoPasses full(9), merged(9);
  ASSERT_TRUE(full.graph.optimize().usable);
  ASSERT_TRUE(merged.graph.optimize().usable);
  std::vector<Eigen::Isometry3d> T_into_gone;
  for (int k = 0; k < TwoPasses::kPass; ++k) {
    T_into_gone.push_back(merged.graph.pose(k + TwoPasses::kPass).inverse() * merged.graph.pose(k));
    merged.graph.mergeNode(k, k + TwoPasses::kPass);
  }
  // One pass left: 40 nodes, the second pass's odometry fused with the first's, the loop edges gone (inside the
  // merged bodies) and the first pass's closing step 39 -> 40 now 79 -> 40.
  EXPECT_EQ(merged.graph.size(), 40u);
  EXPECT_EQ(merged.graph.edgeCount(), 40u);
  EXPECT_TRUE(merged.graph.isFixed(TwoPasses::kPass)) << "node 0's gauge goes to the node it merged into";
  const PoseGraphResult r = merged.graph.optimize();
  ASSERT_TRUE(r.usable) << r.reason;
  // Already at the optimum to first order: what moves is the fused odometry's second-order part (5-cm steps:
  // ~1e-4 m a step, along a chain of 40), under a millimetre against the odometry's 5 cm (measured: 0.38 mm).
  EXPECT_LT(positionGap(full.graph, merged.graph, TwoPasses::kPass, 2 * TwoPasses::kPass - 1), 1e-3);

  // A new loop, the end of the second pass to the start of the first, 0.2 m off the estimate: the merged graph
  // follows it as the full one does, to within a tenth of the correction.
  const Eigen::Isometry3d T_0_79 = full.graph.pose(0).inverse() * full.graph.pose(79);
  const Eigen::Isometry3d measured = T_0_79 * expSE3((Vector6d() << 0.2, 0, 0, 0, 0, 0.01).finished());
  const Matrix6d tight = Matrix6d::Identity() * 1e4;
  std::vector<Eigen::Isometry3d> before;  // relative to node 40
  for (int k = TwoPasses::kPass; k < 2 * TwoPasses::kPass; ++k)
    before.push_back(full.graph.pose(TwoPasses::kPass).inverse() * full.graph.pose(k));
  full.graph.addEdge(0, 79, measured, tight, EdgeKind::kLoop);
  merged.graph.addEdge(40, 79, T_into_gone[0] * measured, tight, EdgeKind::kLoop);
  ASSERT_TRUE(full.graph.optimize().usable);
  ASSERT_TRUE(merged.graph.optimize().usable);
  double moved = 0;
  for (int k = TwoPasses::kPass; k < 2 * TwoPasses::kPass; ++k)
    moved = std::max(moved, ((full.graph.pose(TwoPasses::kPass).inverse() * full.graph.pose(k)).translation() -
                             before[k - TwoPasses::kPass].translation())
                                .norm());
  ASSERT_GT(moved, 0.02);
  std::printf("new loop: moved the second pass by up to %.4f m; merged vs full graph: %.4f m\n", moved,
              positionGap(full.graph, merged.graph, TwoPasses::kPass, 2 * TwoPasses::kPass - 1));
  EXPECT_LT(positionGap(full.graph, merged.graph, TwoPasses::kPass, 2 * TwoPasses::kPass - 1), 0.1 * moved);
}

TEST(PoseGraphMerge, MergingRefusesUnknownNodesAndItself) {
  PoseGraph g;
  g.addNode(0, Eigen::Isometry3d::Identity());
  g.addNode(1, Eigen::Isometry3d::Identity());
  EXPECT_THROW(g.mergeNode(0, 0), std::invalid_argument);
  EXPECT_THROW(g.mergeNode(0, 5), std::invalid_argument);
  EXPECT_THROW(g.mergeNode(5, 0), std::invalid_argument);
  const std::size_t e = g.addEdge(0, 1, Eigen::Isometry3d::Identity(), Matrix6d::Identity(), EdgeKind::kOdometry);
  g.mergeNode(0, 1);
  EXPECT_EQ(g.size(), 1u);
  EXPECT_EQ(g.edgeCount(), 0u) << "the edge between the merged nodes carries nothing";
  EXPECT_THROW(g.edge(e), std::invalid_argument);
}

}  // namespace
}  // namespace drover::backend
