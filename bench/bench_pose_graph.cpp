// Pose-graph optimisation (issue 5): parking-garage.g2o (1661 poses, 6275 edges) from its initial values with the
// backend's PoseGraph, against a plain Ceres Levenberg-Marquardt solve with sparse Cholesky on the same residuals
// (tests/support/plain_pose_graph_lm.hpp), and the warm re-solve after one more loop edge -- what the pipeline
// pays per accepted loop. Times are the solver's wall time (manual time: building the graph is not counted).
// Bound: <= 2 s for the garage from its initial values.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <optional>
#include <string>

#include "backend/pose_graph.hpp"
#include "io/g2o_io.hpp"
#include "io/odometry/g2o_pose_graph.hpp"
#include "support/plain_pose_graph_lm.hpp"
#include "support/shared_data.hpp"

namespace {

namespace backend = drover::backend;
namespace io = drover::io;

const io::G2oGraph* garage() {
  static const std::optional<io::G2oGraph> graph = []() -> std::optional<io::G2oGraph> {
    const auto path = drover::test::sharedData("g2o/parking-garage.g2o");
    if (!std::filesystem::exists(path)) return std::nullopt;
    return io::readG2o(path.string());
  }();
  return graph ? &*graph : nullptr;
}

backend::PoseGraphConfig plainConfig(int threads) {
  backend::PoseGraphConfig config;
  config.loop_loss = backend::RobustLoss::kNone;  // as the reference: every g2o edge is trusted
  config.threads = threads;
  return config;
}

void BM_PoseGraphParkingGarage(benchmark::State& state) {
  const io::G2oGraph* g2o = garage();
  if (!g2o) return state.SkipWithError("../shared/data/g2o/parking-garage.g2o not found");
  backend::PoseGraphResult r;
  for (auto _ : state) {
    backend::PoseGraph graph = io::toPoseGraph(*g2o, plainConfig(static_cast<int>(state.range(0))));
    r = graph.optimize();
    if (!r.usable) return state.SkipWithError(r.reason.c_str());
    state.SetIterationTime(r.time_ms / 1000);
  }
  state.counters["initial_cost"] = r.initial_cost;
  state.counters["final_cost"] = r.final_cost;
  state.counters["iterations"] = r.iterations;
  state.counters["nodes"] = r.nodes;
  state.counters["edges"] = r.edges;
}
BENCHMARK(BM_PoseGraphParkingGarage)->Arg(1)->Arg(2)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

void BM_PlainCeresLmParkingGarage(benchmark::State& state) {
  const io::G2oGraph* g2o = garage();
  if (!g2o) return state.SkipWithError("../shared/data/g2o/parking-garage.g2o not found");
  drover::test::PlainLmResult r;
  for (auto _ : state) {
    r = drover::test::plainLevenbergMarquardt(*g2o, backend::PoseGraphConfig{}.max_iterations);
    state.SetIterationTime(r.time_ms / 1000);
  }
  state.counters["initial_cost"] = r.initial_cost;
  state.counters["final_cost"] = r.final_cost;
  state.counters["iterations"] = r.iterations;
}
BENCHMARK(BM_PlainCeresLmParkingGarage)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

// The garage solved without its last loop edge; each iteration adds that edge back, re-solves warm (timed),
// then disables it and re-solves (untimed) to start the next iteration from the same state. Loop edges get the
// default Huber loss here, as in the pipeline.
void BM_PoseGraphWarmResolveAfterOneLoop(benchmark::State& state) {
  const io::G2oGraph* g2o = garage();
  if (!g2o) return state.SkipWithError("../shared/data/g2o/parking-garage.g2o not found");
  backend::PoseGraph graph = io::toPoseGraph(*g2o, backend::PoseGraphConfig{});
  std::size_t loop = graph.edgeCount();
  while (loop-- > 0 && graph.edge(loop).kind != backend::EdgeKind::kLoop) {
  }
  graph.setEdgeEnabled(loop, false);
  graph.optimize();
  backend::PoseGraphResult r;
  for (auto _ : state) {
    graph.setEdgeEnabled(loop, true);
    r = graph.optimize();
    state.SetIterationTime(r.time_ms / 1000);
    graph.setEdgeEnabled(loop, false);
    graph.optimize();
  }
  state.counters["iterations"] = r.iterations;
  state.counters["initial_cost"] = r.initial_cost;
  state.counters["final_cost"] = r.final_cost;
}
BENCHMARK(BM_PoseGraphWarmResolveAfterOneLoop)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace

BENCHMARK_MAIN();
