// Trajectory evaluation throughput: APE (time association, SE(3) Umeyama alignment, per-pose errors and
// statistics) on 10^6 poses, and the parts on their own. The estimate is the reference moved rigidly plus a
// deterministic wiggle, with stamps 2 ms late so that association does real nearest-stamp searches.
#include <benchmark/benchmark.h>

#include <cmath>

#include "eval/ape.hpp"
#include "eval/rpe.hpp"
#include "geometry/so3.hpp"

namespace {

using drover::StampedPose;
using drover::Time;
using drover::Trajectory;
namespace eval = drover::eval;

constexpr int kPoses = 1'000'000;

Eigen::Isometry3d pose(const Eigen::Vector3d& rotvec, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = drover::geometry::expSO3(rotvec);
  T.translation() = t;
  return T;
}

struct Data {
  Trajectory ref, est;
  Data() {
    const Eigen::Isometry3d T = pose(Eigen::Vector3d(0.1, -0.2, 1.0), Eigen::Vector3d(10, -5, 2));
    ref.reserve(kPoses);
    est.reserve(kPoses);
    for (int i = 0; i < kPoses; ++i) {
      const double a = 1e-4 * i;
      const Time t = static_cast<Time>(i) * 10'000'000;  // 100 Hz
      const Eigen::Isometry3d P = pose(Eigen::Vector3d(0, 0.01 * std::sin(a), a),
                                       Eigen::Vector3d(50 * std::cos(a), 30 * std::sin(a), std::sin(7 * a)));
      ref.push_back({t, P});
      const Eigen::Isometry3d wiggle =
          pose(Eigen::Vector3d(1e-3 * std::sin(i), 0, 0), Eigen::Vector3d(0.01 * std::cos(i), 0, 0));
      est.push_back({t + 2'000'000, T * P * wiggle});
    }
  }
};

const Data& data() {
  static const Data d;
  return d;
}

void BM_ApeSe3WithStatistics(benchmark::State& state) {
  const Data& d = data();
  eval::ApeOptions o;
  o.alignment = eval::Alignment::kSe3;
  for (auto _ : state) {
    const eval::ApeResult r = eval::computeApe(d.ref, d.est, o);
    benchmark::DoNotOptimize(r.stats.rmse);
  }
  state.SetItemsProcessed(state.iterations() * kPoses);
}
BENCHMARK(BM_ApeSe3WithStatistics)->Unit(benchmark::kMillisecond);

void BM_Association(benchmark::State& state) {
  const Data& d = data();
  for (auto _ : state) benchmark::DoNotOptimize(eval::associate(d.ref, d.est).size());
  state.SetItemsProcessed(state.iterations() * kPoses);
}
BENCHMARK(BM_Association)->Unit(benchmark::kMillisecond);

void BM_UmeyamaSe3(benchmark::State& state) {
  const Data& d = data();
  const Eigen::Matrix3Xd x = eval::positionsOf(d.est), y = eval::positionsOf(d.ref);
  for (auto _ : state) benchmark::DoNotOptimize(eval::umeyamaAlignment(x, y, false).t);
  state.SetItemsProcessed(state.iterations() * kPoses);
}
BENCHMARK(BM_UmeyamaSe3)->Unit(benchmark::kMillisecond);

void BM_RpeTenFramesRotationAngle(benchmark::State& state) {
  const Data& d = data();
  eval::RpeOptions o;
  o.delta = 10;
  o.relation = eval::PoseRelation::kAngleDeg;
  for (auto _ : state) benchmark::DoNotOptimize(eval::computeRpe(d.ref, d.est, o).stats.mean);
  state.SetItemsProcessed(state.iterations() * kPoses);
}
BENCHMARK(BM_RpeTenFramesRotationAngle)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
