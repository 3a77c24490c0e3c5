// g2o graphs <-> backend::PoseGraph (io/odometry/g2o_pose_graph.hpp): the information mapping, edge kinds, FIX,
// errors with their line, and the parking-garage benchmark against a plain Ceres Levenberg-Marquardt solve.
// (In tests/cli because that test module links drover_io_odometry.)
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "geometry/se3.hpp"
#include "geometry/so3.hpp"
#include "io/error.hpp"
#include "io/g2o_io.hpp"
#include "io/odometry/g2o_pose_graph.hpp"
#include "support/expect_io_error.hpp"
#include "support/plain_pose_graph_lm.hpp"
#include "support/shared_data.hpp"

namespace drover::io {
namespace {

using backend::EdgeKind;
using backend::Matrix6d;
using Vector6d = Eigen::Matrix<double, 6, 1>;

Matrix6d randomInformation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A.data()[i] = u(rng);
  return A * A.transpose() + 0.5 * Matrix6d::Identity();
}

// g2o's EdgeSE3 error for the measurement Z at the relative pose T_ij: [t; qv] of Z^-1 T_ij, w >= 0.
Vector6d g2oError(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_ij) {
  const Eigen::Isometry3d delta = geometry::inverse(Z) * T_ij;
  Eigen::Quaterniond q(delta.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  Vector6d e;
  e << delta.translation(), q.vec();
  return e;
}

// Drover's RelativePoseFactor error, unwhitened.
Vector6d droverError(const Eigen::Isometry3d& Z, const Eigen::Isometry3d& T_ij) {
  Vector6d r;
  r << T_ij.translation() - Z.translation(), geometry::logSO3(Z.linear().transpose() * T_ij.linear());
  return r;
}

TEST(G2oPoseGraph, TheMappedInformationGivesG2osChiSquareForSmallErrorsAndMapsBackExactly) {
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 5; ++trial) {
    Vector6d xi;
    for (int i = 0; i < 6; ++i) xi(i) = 2 * n(rng);
    const Eigen::Isometry3d Z = geometry::expSE3(xi);
    const Matrix6d info_g2o = randomInformation(rng);
    const Matrix6d info = informationFromG2o(info_g2o, Z.linear());
    for (int i = 0; i < 6; ++i) xi(i) = 1e-4 * n(rng);
    const Eigen::Isometry3d T_ij = Z * geometry::expSE3(xi);
    const Vector6d e = g2oError(Z, T_ij), r = droverError(Z, T_ij);
    EXPECT_NEAR(r.dot(info * r) / e.dot(info_g2o * e), 1.0, 1e-6);
    EXPECT_TRUE(informationToG2o(info, Z.linear()).isApprox(info_g2o, 1e-12));
  }
  // The isotropic case in numbers: rotation block / 4.
  const Matrix6d diag = (Vector6d() << 1, 1, 1, 4, 4, 4).finished().asDiagonal();
  EXPECT_TRUE(informationFromG2o(diag, Eigen::Matrix3d::Identity()).isApprox(Matrix6d::Identity(), 1e-15));
}

G2oGraph chainWithLoop() {
  G2oGraph g;
  for (int k = 0; k < 5; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation().x() = k;
    g.vertices.push_back(G2oVertex{k, T, std::size_t(k + 1)});
  }
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.translation().x() = 1;
  for (int k = 1; k < 5; ++k) g.edges.push_back(G2oEdge{k - 1, k, step, Matrix6d::Identity(), std::size_t(k + 5)});
  g.edges.push_back(G2oEdge{4, 0, g.vertices[4].T_world_vertex.inverse() * g.vertices[0].T_world_vertex,
                            Matrix6d::Identity(), 10});
  return g;
}

TEST(G2oPoseGraph, ConsecutiveIdsAreOdometryOtherEdgesLoopsAndTheFirstVertexIsTheGauge) {
  const backend::PoseGraph graph = toPoseGraph(chainWithLoop());
  EXPECT_EQ(graph.size(), 5u);
  ASSERT_EQ(graph.edgeCount(), 5u);
  EXPECT_EQ(graph.edge(0).kind, EdgeKind::kOdometry);
  EXPECT_EQ(graph.edge(4).kind, EdgeKind::kLoop);
  EXPECT_TRUE(graph.isFixed(0));
  EXPECT_FALSE(graph.isFixed(1));
  EXPECT_TRUE(graph.edge(0).information.isApprox(informationFromG2o(Matrix6d::Identity(), Eigen::Matrix3d::Identity())));
}

TEST(G2oPoseGraph, FixLinesReplaceTheDefaultGaugeAndSurviveTheWayBack) {
  G2oGraph g = chainWithLoop();
  g.fixed = {2, 3};
  const backend::PoseGraph graph = toPoseGraph(g);
  EXPECT_FALSE(graph.isFixed(0));
  EXPECT_TRUE(graph.isFixed(2));
  EXPECT_TRUE(graph.isFixed(3));
  const G2oGraph back = toG2o(graph);
  EXPECT_EQ(back.fixed, (std::vector<int>{2, 3}));
  ASSERT_EQ(back.edges.size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_TRUE(back.edges[i].information.isApprox(g.edges[i].information, 1e-15));
}

TEST(G2oPoseGraph, GraphErrorsBecomeIoErrorsNamingTheFileAndTheLine) {
  G2oGraph g = chainWithLoop();
  g.vertices.push_back(G2oVertex{3, Eigen::Isometry3d::Identity(), 42});
  test::expectIoError([&] { toPoseGraph(g, {}, "garage.g2o"); }, {"garage.g2o (line 42)", "duplicate node id 3"});
  g = chainWithLoop();
  g.edges[2].information(0, 0) = -5;
  test::expectIoError([&] { toPoseGraph(g, {}, "garage.g2o"); }, {"garage.g2o (line 8)", "positive semi-definite"});
  g = chainWithLoop();
  g.fixed = {9};
  test::expectIoError([&] { toPoseGraph(g, {}, "garage.g2o"); }, {"garage.g2o", "unknown node id 9"});
}

TEST(G2oPoseGraph, OptimisedPosesGoBackIntoTheVerticesAndPriorsCannotBeWritten) {
  G2oGraph g = chainWithLoop();
  g.vertices[3].T_world_vertex.translation().y() = 0.7;  // off the consistent chain
  backend::PoseGraph graph = toPoseGraph(g);
  const backend::PoseGraphResult r = graph.optimize();
  ASSERT_TRUE(r.converged) << r.reason;
  updateVertexPoses(g, graph);
  EXPECT_NEAR(g.vertices[3].T_world_vertex.translation().y(), 0.0, 1e-6);
  EXPECT_EQ(g.edges.size(), 5u);
  graph.addPrior(2, Eigen::Isometry3d::Identity(), Matrix6d::Identity());
  EXPECT_THROW(toG2o(graph), std::invalid_argument);
  backend::PoseGraph other;
  other.addNode(0, Eigen::Isometry3d::Identity());
  EXPECT_THROW(updateVertexPoses(g, other), std::invalid_argument);
}

// The benchmark: 1661 poses, 6275 edges. The solve must end no higher than a plain Ceres LM with sparse
// Cholesky from the same start (speed is bench/bench_pose_graph.cpp's business; the time is recorded only).
TEST(G2oPoseGraph, ParkingGarageEndsNoHigherThanAPlainCeresLevenbergMarquardtSolve) {
  const auto path = test::sharedData("g2o/parking-garage.g2o");
  DROVER_REQUIRE_SHARED(path);
  const G2oGraph g2o = readG2o(path.string());
  backend::PoseGraphConfig config;
  config.loop_loss = backend::RobustLoss::kNone;  // the reference has no loss
  backend::PoseGraph graph = toPoseGraph(g2o, config, path.string());
  const backend::PoseGraphResult ours = graph.optimize();
  const test::PlainLmResult plain = test::plainLevenbergMarquardt(g2o, config.max_iterations);
  ASSERT_TRUE(ours.usable) << ours.reason;
  ASSERT_TRUE(plain.usable);
  EXPECT_TRUE(ours.converged) << ours.reason;
  EXPECT_NEAR(ours.initial_cost, plain.initial_cost, 1e-9 * plain.initial_cost);  // the same problem
  EXPECT_GT(ours.initial_cost, 100 * ours.final_cost);
  EXPECT_LE(ours.final_cost, plain.final_cost * (1 + 1e-9));
  EXPECT_EQ(ours.nodes, 1661);
  EXPECT_EQ(ours.edges, 6275);
  RecordProperty("initial_cost", std::to_string(ours.initial_cost));
  RecordProperty("final_cost", std::to_string(ours.final_cost));
  RecordProperty("plain_lm_final_cost", std::to_string(plain.final_cost));
  RecordProperty("time_ms", std::to_string(ours.time_ms));
  std::printf("parking-garage: initial %.6g, final %.9g (plain LM %.9g, %d its), %d iterations, %.0f ms (plain %.0f)\n",
              ours.initial_cost, ours.final_cost, plain.final_cost, plain.iterations, ours.iterations, ours.time_ms,
              plain.time_ms);
}

}  // namespace
}  // namespace drover::io
