// The backend gives the same bits whatever addresses its blocks get. A run's heap differs from run to run (the
// reader's and the workers' threads allocate as they please), so a result that depended on the order of
// addresses would make two replays of one course differ. Each test builds the same estimate twice, once in the
// heap as it is and once after the heap was riddled with holes, so that the second one's blocks land at
// addresses in no particular order (~100 of 179 pose-graph nodes below an earlier one, measured), and compares
// the results bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "backend/fixed_lag_smoother.hpp"
#include "backend/pose_graph.hpp"
#include "geometry/se3.hpp"
#include "pose_graph_test_util.hpp"
#include "smoother_test_util.hpp"

namespace drover::backend {
namespace {

// Allocates blocks of mixed sizes and frees every other one in random order: later allocations of those sizes
// take the holes in the allocator's free-list order, not in address order. The rest stays allocated.
std::vector<std::unique_ptr<char[]>> riddleTheHeap(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<std::unique_ptr<char[]>> blocks;
  for (int i = 0; i < 20000; ++i) {
    blocks.push_back(std::make_unique<char[]>(16 + 16 * (rng() % 256)));  // 16 B to 4 KiB
    std::memset(blocks.back().get(), 0, 16);
  }
  std::vector<std::size_t> order(blocks.size() / 2);
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = 2 * i + 1;
  std::shuffle(order.begin(), order.end(), rng);
  for (std::size_t i : order) blocks[i].reset();
  return blocks;
}

// Three turns of the helix (60 poses a turn) with noisy odometry, and a loop edge from every third pose of the
// second and third turns to the same place one turn before: many cycles, so the sparse Cholesky's fill-reducing
// ordering has choices to make.
void buildThreeTurns(PoseGraph& graph) {
  constexpr int kPerTurn = 60, kTurns = 3;
  const std::vector<Eigen::Isometry3d> turn = test::helix(kPerTurn);
  std::mt19937 rng(11);
  const auto truth = [&](int k) { return turn[static_cast<std::size_t>(k % kPerTurn)]; };
  Eigen::Isometry3d chained = truth(0);
  graph.addNode(0, chained);
  for (int k = 1; k < kPerTurn * kTurns; ++k) {
    const Eigen::Isometry3d measured =
        geometry::inverse(truth(k - 1)) * truth(k) * geometry::expSE3(test::randomTangent(rng, 0.05, 0.01));
    chained = chained * measured;
    graph.addNode(k, chained);
    graph.addEdge(k - 1, k, measured, test::information(0.05, 0.01), EdgeKind::kOdometry);
    if (k >= kPerTurn && k % 3 == 0)
      graph.addEdge(k - kPerTurn, k, Eigen::Isometry3d::Identity(), test::information(0.02, 0.005), EdgeKind::kLoop);
  }
}

TEST(AddressIndependence, ThePoseGraphSolvesToTheSameBitsWhereverItsNodesLie) {
  PoseGraph plain;
  buildThreeTurns(plain);
  const std::vector<std::unique_ptr<char[]>> kept = riddleTheHeap(5);
  PoseGraph riddled;
  buildThreeTurns(riddled);
  const PoseGraphResult a = plain.optimize(), b = riddled.optimize();
  ASSERT_TRUE(a.usable && b.usable) << a.reason << " / " << b.reason;
  EXPECT_EQ(a.iterations, b.iterations);
  int differing = 0;
  for (int id : plain.nodeIds()) differing += plain.pose(id).matrix() != riddled.pose(id).matrix() ? 1 : 0;
  EXPECT_EQ(differing, 0) << "of " << plain.size() << " nodes";
}

// A loop correction restarts the smoother with the window's bias covariance (pipeline::ImuFusion::reanchor), so
// that covariance must not depend on where the window's states lie (the computation works on a copy of the
// window, allocated anew at each call). ceres::Covariance, used before, orders its columns by the blocks'
// addresses: its last bits changed with the heap, and every replay with a loop closure differed from its first
// loop on (this test fails on it).
TEST(AddressIndependence, TheSmoothersBiasCovarianceIsTheSameBitsWhereverItsStatesLie) {
  constexpr Time kLidarPeriod = 100'000'000;  // [ns] 10 Hz
  const test::Scenario s;
  FixedLagSmoother smoother;
  smoother.initialize(s.truth(0), imu::ImuBias{}, s.preintegration);
  test::PoseNoise noise;
  for (int k = 1; k <= 30; ++k) {
    const Time t0 = (k - 1) * kLidarPeriod, t1 = k * kLidarPeriod;
    ASSERT_TRUE(smoother.update(test::preintegrate(s, t0, t1, smoother.bias()), noise.apply(s.truth(t1).T_world_imu)).ok);
  }
  const std::optional<Eigen::Matrix<double, 6, 6>> plain = smoother.biasCovariance();
  for (unsigned seed : {5u, 6u, 7u}) {
    const std::vector<std::unique_ptr<char[]>> kept = riddleTheHeap(seed);
    const std::optional<Eigen::Matrix<double, 6, 6>> riddled = smoother.biasCovariance();
    ASSERT_TRUE(plain && riddled);
    EXPECT_EQ(*plain, *riddled) << "heap riddled with seed " << seed << ": max difference "
                                << (*plain - *riddled).cwiseAbs().maxCoeff();
  }
}

}  // namespace
}  // namespace drover::backend
