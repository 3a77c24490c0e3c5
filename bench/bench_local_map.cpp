// Speed of the local map's rebuild, the LIS's dearest stage on a car: at 8 m/s nearly every sweep is a keyframe
// (one a metre), and each one reassembles the keyframes within 50 m plus the last 10 s (~130 on kitti05-replay),
// voxel-downsamples them and indexes them again. Inputs are synthetic: keyframes of a straight road between two
// building fronts, every metre, with the point counts of kitti05-replay's VLP-16 sweeps (~6000 planes, ~430 edges).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>

#include "bench/heap_tuned_main.hpp"
#include "lidar/local_map.hpp"
#include "lidar/local_map_voxel.hpp"
#include "lidar/scan_matcher.hpp"
#include "support/voxel_sort_reference.hpp"

namespace {

namespace lidar = drover::lidar;

// One sweep's features in its lidar frame: the road and its verges 1.7 m below and building fronts 30 m to either
// side, out to 60 m, spread so that a 130-keyframe local map keeps about one 0.4 m voxel per three points, as
// kitti05-replay's do (~6000 planes and ~430 edges a sweep).
lidar::FeatureSet roadSweep(unsigned seed, double t_s) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> along(-60.0f, 60.0f), across(-30.0f, 30.0f), up(-1.7f, 13.0f);
  lidar::FeatureSet f;
  f.t = drover::fromSeconds(t_s);
  for (int i = 0; i < 6000; ++i) {
    if (i % 2 == 0) f.planes.emplace_back(along(rng), across(rng), -1.7f);
    else f.planes.emplace_back(along(rng), i % 4 == 1 ? 30.0f : -30.0f, up(rng));
  }
  for (int i = 0; i < 430; ++i) f.edges.emplace_back(std::round(along(rng) / 5.0f) * 5.0f, 30.0f, up(rng));
  return f;
}

Eigen::Isometry3d along(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation().x() = x;
  return T;
}

// The clouds one rebuild downsamples: the planes of the keyframes of a local map, concatenated in the world.
const lidar::PointCloud& assembledPlanes() {
  static const lidar::PointCloud cloud = [] {
    lidar::LocalMap map;
    for (int k = 0; k < 130; ++k) map.addKeyframe(roadSweep(k, 0.13 * k), along(k));
    lidar::PointCloud all;
    for (std::size_t k = 0; k < map.size(); ++k) {
      for (const auto& p : map.keyframe(k).features().planes) all.push_back(p + Eigen::Vector3f(float(k), 0, 0));
    }
    return all;
  }();
  return cloud;
}

// arg 0: the comparison sort it replaced; 1: the radix sort the local map uses.
void BM_VoxelDownsampleLocalMapPlanes(benchmark::State& state) {
  const lidar::PointCloud& cloud = assembledPlanes();
  for (auto _ : state) {
    lidar::PointCloud out = state.range(0) == 0 ? drover::testing::voxelDownsampleBySort(cloud, 0.4f)
                                                : lidar::detail::voxelDownsample(cloud, 0.4f);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["points_in"] = static_cast<double>(cloud.size());
  state.counters["voxels"] = static_cast<double>(lidar::detail::voxelDownsample(cloud, 0.4f).size());
}
BENCHMARK(BM_VoxelDownsampleLocalMapPlanes)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

// A car's keyframe: add one a metre on and rebuild the local map around it (130 keyframes in the map).
void BM_LocalMapRebuildAfterKeyframe(benchmark::State& state) {
  lidar::LocalMap map;
  int k = 0;
  for (; k < 130; ++k) map.addKeyframe(roadSweep(k, 0.13 * k), along(k));
  map.build(along(k - 1).translation());
  std::vector<lidar::FeatureSet> next;
  for (int i = 0; i < 64; ++i) next.push_back(roadSweep(1000 + i, 0.13 * (k + i)));
  std::size_t i = 0;
  for (auto _ : state) {
    state.PauseTiming();
    map.addKeyframe(next[i % next.size()], along(k));
    state.ResumeTiming();
    const lidar::LocalMapBuild b = map.build(along(k).translation());
    benchmark::DoNotOptimize(b.plane_points);
    ++k;
    ++i;
  }
  state.counters["keyframes"] = static_cast<double>(map.assembledKeyframes().size());
  state.counters["plane_points"] = static_cast<double>(map.planesWorld().size());
}
BENCHMARK(BM_LocalMapRebuildAfterKeyframe)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(64);

// The scan matcher on the same road: a sweep 1 m past the newest keyframe, the guess 0.2 m across the road and
// 1 deg off (along it the synthetic road is alike everywhere).
// arg 0: every fit recomputed in every iteration (before); 1: fits reused where the neighbours return (now).
void BM_ScanMatcherAlignOnRoad(benchmark::State& state) {
  lidar::LocalMap map;
  for (int k = 0; k < 130; ++k) map.addKeyframe(roadSweep(k, 0.13 * k), along(k));
  map.build(along(130).translation());
  const lidar::FeatureSet sweep = roadSweep(5000, 0.13 * 130);
  lidar::ScanMatcherConfig config;
  config.reuse_fits = state.range(0) == 1;
  const lidar::ScanMatcher matcher(config);
  Eigen::Isometry3d guess = along(130.0);
  guess.translation().y() = 0.2;
  guess.linear() = Eigen::AngleAxisd(0.0175, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  lidar::MatchResult result;
  for (auto _ : state) {
    result = matcher.align(sweep, map, guess);
    benchmark::DoNotOptimize(result.T_world_lidar);
  }
  state.counters["iterations"] = result.iterations;
  state.counters["fits_reused_share"] =
      static_cast<double>(result.fits_reused) / std::max(1, result.fits_computed + result.fits_reused);
}
BENCHMARK(BM_ScanMatcherAlignOnRoad)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

// As `drover run` does (apps/drover/heap_tuning.hpp).
int main(int argc, char** argv) { return drover::bench::runWithTunedHeap(argc, argv); }
