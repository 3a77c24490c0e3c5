// PoseGraph on synthetic graphs with exact ground truth: a loop of poses on a helix, odometry edges between
// consecutive poses and loop edges back to the start.
#include "backend/pose_graph.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"
#include "pose_graph_test_util.hpp"

namespace drover::backend {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using geometry::expSE3;
using geometry::inverse;

using test::helix;
using test::information;
using test::randomTangent;

Eigen::Isometry3d relative(const Eigen::Isometry3d& A, const Eigen::Isometry3d& B) { return inverse(A) * B; }

// Mean position error [m] of the graph against the truth.
double meanPositionError(const PoseGraph& graph, const std::vector<Eigen::Isometry3d>& truth) {
  double sum = 0;
  for (int k = 0; k < static_cast<int>(truth.size()); ++k)
    sum += (graph.pose(k).translation() - truth[k].translation()).norm();
  return sum / truth.size();
}

// Odometry with noise (sigmas 0.05 m, 0.01 rad) chained from the true first pose as the initial values, and one
// loop edge last -> first measured exactly (within its own sigma 0.01 m, 0.002 rad).
struct NoisyLoop {
  std::vector<Eigen::Isometry3d> truth = helix(40);
  PoseGraph graph;

  explicit NoisyLoop(const PoseGraphConfig& config = {}, unsigned seed = 3) : graph(config) {
    std::mt19937 rng(seed);
    Eigen::Isometry3d chained = truth[0];
    graph.addNode(0, chained);
    for (int k = 1; k < static_cast<int>(truth.size()); ++k) {
      const Eigen::Isometry3d measured = relative(truth[k - 1], truth[k]) * expSE3(randomTangent(rng, 0.05, 0.01));
      chained = chained * measured;
      graph.addNode(k, chained);
      graph.addEdge(k - 1, k, measured, information(0.05, 0.01), EdgeKind::kOdometry);
    }
  }
  int last() const { return static_cast<int>(truth.size()) - 1; }
  std::size_t addTrueLoop() {
    return graph.addEdge(last(), 0, relative(truth[last()], truth[0]), information(0.01, 0.002), EdgeKind::kLoop);
  }
};

TEST(PoseGraph, ALoopEdgeBringsNoisyOdometryCloserToTheTruthThanOdometryAlone) {
  NoisyLoop loop;
  const double odometry_error = meanPositionError(loop.graph, loop.truth);
  const double odometry_end_error = (loop.graph.pose(loop.last()).translation() - loop.truth.back().translation()).norm();
  ASSERT_GT(odometry_error, 0.2);  // the chained noise really drifts
  loop.addTrueLoop();
  const PoseGraphResult r = loop.graph.optimize();
  EXPECT_TRUE(r.converged) << r.reason;
  EXPECT_LT(r.final_cost, r.initial_cost);
  EXPECT_EQ(r.nodes, 40);
  EXPECT_EQ(r.edges, 40);
  EXPECT_GE(r.iterations, 1);
  // The loop pins the end of the chain; in between the error is a bridge instead of a random walk.
  EXPECT_LT(meanPositionError(loop.graph, loop.truth), 0.8 * odometry_error);
  EXPECT_LT((loop.graph.pose(loop.last()).translation() - loop.truth.back().translation()).norm(),
            0.1 * odometry_end_error);
  EXPECT_NEAR(loop.graph.cost(), r.final_cost, 1e-9 * r.initial_cost);
}

TEST(PoseGraph, ANoiseFreeGraphConvergesBackToTheTruthFromPerturbedPoses) {
  const std::vector<Eigen::Isometry3d> truth = helix(30);
  PoseGraph graph;
  std::mt19937 rng(11);
  for (int k = 0; k < 30; ++k) graph.addNode(k, k == 0 ? truth[0] : truth[k] * expSE3(randomTangent(rng, 0.3, 0.1)));
  for (int k = 1; k < 30; ++k)
    graph.addEdge(k - 1, k, relative(truth[k - 1], truth[k]), information(0.1, 0.01), EdgeKind::kOdometry);
  graph.addEdge(29, 0, relative(truth[29], truth[0]), information(0.1, 0.01), EdgeKind::kLoop);
  graph.addEdge(5, 20, relative(truth[5], truth[20]), information(0.1, 0.01), EdgeKind::kLoop);
  EXPECT_GT(graph.cost(), 100.0);
  const PoseGraphResult r = graph.optimize();
  ASSERT_TRUE(r.usable) << r.reason;
  EXPECT_LT(r.final_cost, 1e-12);
  for (int k = 0; k < 30; ++k) {
    EXPECT_LT((graph.pose(k).translation() - truth[k].translation()).norm(), 1e-6) << "node " << k;
    EXPECT_LT(geometry::logSO3(truth[k].linear().transpose() * graph.pose(k).linear()).norm(), 1e-6) << k;
  }
}

// Harm of a wrong loop edge (it claims node 20 lies 8 m and 0.5 rad from where it is, with the sigmas of a
// plausible ICP loop, 0.1 m and 0.02 rad): mean distance [m] of the poses from the solution without it.
double harmOfAWrongLoop(RobustLoss loss) {
  PoseGraphConfig config;
  config.loop_loss = loss;
  config.function_tolerance = 1e-12;
  NoisyLoop clean(config), dirty(config);
  clean.addTrueLoop();
  dirty.addTrueLoop();
  const Eigen::Isometry3d wrong =
      relative(dirty.truth[20], dirty.truth[0]) * expSE3((Vector6d() << 8, 0, 0, 0, 0, 0.5).finished());
  dirty.graph.addEdge(20, 0, wrong, information(0.1, 0.02), EdgeKind::kLoop);
  EXPECT_TRUE(clean.graph.optimize().converged);
  EXPECT_TRUE(dirty.graph.optimize().converged);
  double sum = 0;
  for (int k = 0; k < 40; ++k) sum += (dirty.graph.pose(k).translation() - clean.graph.pose(k).translation()).norm();
  return sum / 40;
}

TEST(PoseGraph, ARobustLossOnLoopEdgesLimitsTheHarmOfAWrongLoop) {
  const double plain = harmOfAWrongLoop(RobustLoss::kNone);
  const double huber = harmOfAWrongLoop(RobustLoss::kHuber);
  const double cauchy = harmOfAWrongLoop(RobustLoss::kCauchy);
  EXPECT_GT(plain, 0.2);  // least squares spreads the lie over the loop
  EXPECT_LT(huber, 0.6 * plain);
  EXPECT_LT(cauchy, 0.05 * plain);  // Cauchy's influence falls off, Huber's stays constant
}

TEST(PoseGraph, DisablingAWrongLoopEdgeGivesTheSameSolutionAsNeverAddingIt) {
  PoseGraphConfig config;
  config.loop_loss = RobustLoss::kNone;
  config.function_tolerance = 1e-12;
  NoisyLoop clean(config), dirty(config);
  clean.addTrueLoop();
  dirty.addTrueLoop();
  const std::size_t bad = dirty.graph.addEdge(20, 0, Eigen::Isometry3d::Identity(), information(0.01, 0.002),
                                              EdgeKind::kLoop);
  ASSERT_TRUE(dirty.graph.optimize().usable);
  EXPECT_EQ(dirty.graph.edgeCount(), 41u);
  dirty.graph.setEdgeEnabled(bad, false);
  EXPECT_EQ(dirty.graph.edgeCount(), 41u);
  EXPECT_EQ(dirty.graph.enabledEdgeCount(), 40u);
  EXPECT_FALSE(dirty.graph.edge(bad).enabled);
  EXPECT_EQ(dirty.graph.edge(bad).kind, EdgeKind::kLoop);
  ASSERT_TRUE(clean.graph.optimize().usable);
  const PoseGraphResult r = dirty.graph.optimize();  // warm start from the damaged solution
  EXPECT_EQ(r.edges, 40);
  for (int k = 0; k < 40; ++k)
    EXPECT_LT((dirty.graph.pose(k).translation() - clean.graph.pose(k).translation()).norm(), 1e-5) << k;
  dirty.graph.setEdgeEnabled(bad, true);  // and back: the edge takes part again
  EXPECT_EQ(dirty.graph.enabledEdgeCount(), 41u);
  EXPECT_GT(dirty.graph.cost(), 10 * clean.graph.cost());
}

TEST(PoseGraph, GrowingTheGraphAfterASolveAndSolvingAgainMatchesASolveOfTheWholeGraph) {
  PoseGraphConfig config;
  config.function_tolerance = 1e-12;
  NoisyLoop whole(config), grown(config);
  whole.addTrueLoop();
  ASSERT_TRUE(grown.graph.optimize().usable);  // odometry only: consistent already, nothing moves
  grown.addTrueLoop();
  const std::vector<Eigen::Isometry3d> truth = whole.truth;
  // New keyframes beyond the loop, on both graphs (the same measurement).
  for (PoseGraph* g : {&whole.graph, &grown.graph}) {
    g->addNode(40, g->pose(39) * relative(truth[39], truth[1]));
    g->addEdge(39, 40, relative(truth[39], truth[1]), information(0.05, 0.01), EdgeKind::kOdometry);
  }
  const PoseGraphResult a = whole.graph.optimize(), b = grown.graph.optimize();
  ASSERT_TRUE(a.converged && b.converged) << a.reason << " / " << b.reason;
  EXPECT_EQ(b.nodes, 41);
  for (int k = 0; k <= 40; ++k)
    EXPECT_LT((whole.graph.pose(k).translation() - grown.graph.pose(k).translation()).norm(), 1e-5) << k;
  const PoseGraphResult again = grown.graph.optimize();  // warm: already at the minimum
  EXPECT_LE(again.iterations, 2);
  EXPECT_NEAR(again.final_cost, b.final_cost, 1e-9 * b.final_cost + 1e-12);
}

TEST(PoseGraph, FixedNodesStayExactlyWhereTheyAre) {
  NoisyLoop loop;
  loop.addTrueLoop();
  EXPECT_TRUE(loop.graph.isFixed(0));  // the first node added is the gauge
  EXPECT_FALSE(loop.graph.isFixed(10));
  loop.graph.setFixed(10, true);
  const Eigen::Isometry3d T0 = loop.graph.pose(0), T10 = loop.graph.pose(10), T20 = loop.graph.pose(20);
  ASSERT_TRUE(loop.graph.optimize().usable);
  EXPECT_TRUE(loop.graph.pose(0).isApprox(T0, 1e-15));
  EXPECT_TRUE(loop.graph.pose(10).isApprox(T10, 1e-15));
  EXPECT_FALSE(loop.graph.pose(20).isApprox(T20, 1e-6));
}

TEST(PoseGraph, APriorHoldsTheGaugeWhenNoNodeIsFixed) {
  const std::vector<Eigen::Isometry3d> truth = helix(10);
  PoseGraph graph;
  for (int k = 0; k < 10; ++k) graph.addNode(100 + 7 * k, truth[k] * expSE3(Vector6d::Constant(0.05)));
  graph.setFixed(100, false);
  for (int k = 1; k < 10; ++k)
    graph.addEdge(100 + 7 * (k - 1), 100 + 7 * k, relative(truth[k - 1], truth[k]), information(0.1, 0.01),
                  EdgeKind::kOdometry);
  const std::size_t prior = graph.addPrior(100, truth[0], information(0.01, 0.001));
  EXPECT_EQ(graph.edge(prior).kind, EdgeKind::kPrior);
  EXPECT_EQ(graph.edge(prior).to, 100);
  ASSERT_TRUE(graph.optimize().converged);
  EXPECT_EQ(graph.nodeIds().front(), 100);
  for (int k = 0; k < 10; ++k) EXPECT_LT((graph.pose(100 + 7 * k).translation() - truth[k].translation()).norm(), 1e-6);
}

TEST(PoseGraph, AGraphWithoutEdgesHasNothingToOptimise) {
  PoseGraph graph;
  graph.addNode(3, Eigen::Isometry3d::Identity());
  EXPECT_EQ(graph.cost(), 0.0);
  const PoseGraphResult r = graph.optimize();
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_NE(r.reason.find("nothing to optimise"), std::string::npos);
}

TEST(PoseGraph, AllNodesFixedOrNoneFixedStillGivesAUsableAnswer) {
  NoisyLoop all;
  all.addTrueLoop();
  for (int k = 0; k < 40; ++k) all.graph.setFixed(k, true);
  const double before = all.graph.cost();
  const PoseGraphResult r = all.graph.optimize();
  EXPECT_TRUE(r.usable) << r.reason;
  EXPECT_EQ(all.graph.cost(), before);

  NoisyLoop none;  // no gauge: the solution is defined up to a rigid motion, the cost still goes down
  none.addTrueLoop();
  none.graph.setFixed(0, false);
  const PoseGraphResult free = none.graph.optimize();
  EXPECT_TRUE(free.usable) << free.reason;
  NoisyLoop gauge;
  gauge.addTrueLoop();
  EXPECT_NEAR(free.final_cost, gauge.graph.optimize().final_cost, 1e-6 * free.final_cost);
}

template <typename F>
void expectInvalid(F&& f, const std::string& fragment) {
  try {
    f();
    FAIL() << "expected std::invalid_argument with '" << fragment << "'";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(PoseGraph, RejectsDuplicateIdsNonFinitePosesAndUnknownNodes) {
  PoseGraph g;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  g.addNode(1, I);
  g.addNode(2, I);
  expectInvalid([&] { g.addNode(1, I); }, "duplicate node id 1");
  Eigen::Isometry3d bad = I;
  bad.translation().x() = NAN;
  expectInvalid([&] { g.addNode(3, bad); }, "not finite");
  expectInvalid([&] { g.setPose(2, bad); }, "not finite");
  Eigen::Isometry3d sheared = I;
  sheared.linear()(0, 1) = 0.5;
  expectInvalid([&] { g.addNode(3, sheared); }, "no rotation");
  expectInvalid([&] { g.addEdge(1, 7, I, Matrix6d::Identity(), EdgeKind::kOdometry); }, "unknown node id 7");
  expectInvalid([&] { g.addEdge(8, 9, I, Matrix6d::Identity(), EdgeKind::kLoop); }, "unknown node ids 8 and 9");
  expectInvalid([&] { g.addEdge(1, 1, I, Matrix6d::Identity(), EdgeKind::kLoop); }, "two different nodes");
  expectInvalid([&] { g.addEdge(1, 2, bad, Matrix6d::Identity(), EdgeKind::kLoop); }, "measurement is not finite");
  expectInvalid([&] { g.addPrior(5, I, Matrix6d::Identity()); }, "unknown node id 5");
  expectInvalid([&] { g.pose(42); }, "unknown node id 42");
  expectInvalid([&] { g.setFixed(42, true); }, "unknown node id 42");
  expectInvalid([&] { g.edge(0); }, "out of range");
  expectInvalid([&] { g.setEdgeEnabled(3, false); }, "out of range");
  EXPECT_EQ(g.edgeCount(), 0u);  // nothing half-added
}

TEST(PoseGraph, RejectsAnInformationThatIsNotSymmetricPositiveSemiDefinite) {
  PoseGraph g;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  g.addNode(1, I);
  g.addNode(2, I);
  Matrix6d asymmetric = Matrix6d::Identity();
  asymmetric(0, 5) = 0.3;
  expectInvalid([&] { g.addEdge(1, 2, I, asymmetric, EdgeKind::kOdometry); }, "not symmetric");
  Matrix6d indefinite = Matrix6d::Identity();
  indefinite(4, 4) = -1;
  expectInvalid([&] { g.addEdge(1, 2, I, indefinite, EdgeKind::kOdometry); }, "not positive semi-definite");
  expectInvalid([&] { g.addEdge(1, 2, I, Matrix6d::Zero(), EdgeKind::kOdometry); }, "information is zero");
  Matrix6d nan = Matrix6d::Identity();
  nan(2, 2) = NAN;
  expectInvalid([&] { g.addEdge(1, 2, I, nan, EdgeKind::kOdometry); }, "information is not finite");
  Matrix6d singular = Matrix6d::Identity();
  singular(5, 5) = 0;  // no yaw information: allowed
  EXPECT_EQ(g.addEdge(1, 2, I, singular, EdgeKind::kOdometry), 0u);
  EXPECT_EQ(g.edgeCount(), 1u);
}

TEST(PoseGraphConfig, ValidateNamesTheBadValueAndTheConstructorRejectsIt) {
  EXPECT_EQ(PoseGraphConfig{}.validate(), "");
  PoseGraphConfig c;
  c.max_iterations = 0;
  EXPECT_NE(c.validate().find("max_iterations = 0"), std::string::npos);
  expectInvalid([&] { PoseGraph g(c); }, "max_iterations");
  c = {};
  c.loop_loss_scale = -1;
  EXPECT_NE(c.validate().find("loop_loss_scale"), std::string::npos);
  c = {};
  c.initial_trust_region_radius = 0;
  EXPECT_NE(c.validate().find("initial_trust_region_radius"), std::string::npos);
  c = {};
  c.threads = 0;
  EXPECT_NE(c.validate().find("threads"), std::string::npos);
  c = {};
  c.function_tolerance = NAN;
  EXPECT_NE(c.validate().find("function_tolerance"), std::string::npos);
  EXPECT_EQ(parseRobustLoss("cauchy"), RobustLoss::kCauchy);
  EXPECT_EQ(robustLossName(parseRobustLoss("huber")), "huber");
  expectInvalid([] { parseRobustLoss("tukey"); }, "unknown loss 'tukey'");
}

TEST(PoseGraph, InformationFromARightPerturbationGivesTheSameMahalanobisDistance) {
  std::mt19937 rng(2);
  const Eigen::Isometry3d T_m = expSE3(randomTangent(rng, 3.0, 1.0));
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Random();
  const Matrix6d info_xi = A * A.transpose() + Matrix6d::Identity();
  const Matrix6d info_r = informationFromRightPerturbation(info_xi, T_m.linear());
  const Vector6d xi = randomTangent(rng, 1e-5, 1e-5);
  const Eigen::Isometry3d T = T_m * expSE3(xi);
  Vector6d r;  // our error at T for the measurement T_m
  r << T.translation() - T_m.translation(), geometry::logSO3(T_m.linear().transpose() * T.linear());
  EXPECT_NEAR(r.dot(info_r * r) / xi.dot(info_xi * xi), 1.0, 1e-4);
}

}  // namespace
}  // namespace drover::backend
