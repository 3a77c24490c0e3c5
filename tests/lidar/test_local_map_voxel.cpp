// The local map's voxel downsampling (radix-sorted keys): the same centroids, in the same order, to the last bit,
// as the comparison sort it replaced, so the odometry's results do not move with the speed-up.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "lidar/local_map_voxel.hpp"
#include "support/voxel_sort_reference.hpp"

namespace drover::lidar {
namespace {

// A road-sized local map: `n` points over a box of the given half sizes [m] around `centre`, a share of them
// piled into a few voxels (a wall seen from many keyframes) so that voxels hold many points.
PointCloud box(std::size_t n, const Eigen::Vector3f& centre, const Eigen::Vector3f& half, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  PointCloud cloud;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f u(unit(rng), unit(rng), unit(rng));
    cloud.push_back(i % 5 == 0 ? Eigen::Vector3f(centre + 0.3f * u) : Eigen::Vector3f(centre + half.cwiseProduct(u)));
  }
  return cloud;
}

void expectSameAsSort(const PointCloud& cloud, float leaf) {
  const PointCloud got = detail::voxelDownsample(cloud, leaf);
  const PointCloud want = testing::voxelDownsampleBySort(cloud, leaf);
  ASSERT_EQ(got.size(), want.size()) << "leaf " << leaf;
  for (std::size_t i = 0; i < want.size(); ++i) {
    // Bitwise: == on floats, not a tolerance.
    ASSERT_TRUE(got[i] == want[i]) << "voxel " << i << ": " << got[i].transpose() << " vs " << want[i].transpose();
  }
}

TEST(LocalMapVoxel, ARoadSizedLocalMapDownsamplesBitForBitAsTheComparisonSort) {
  // 300k points over 150 m x 150 m x 20 m around the origin (cells on both sides of zero) at the plane and edge leaves.
  const PointCloud cloud = box(300'000, {0.0f, 0.0f, 0.0f}, {75.0f, 75.0f, 10.0f}, 1);
  expectSameAsSort(cloud, 0.4f);
  expectSameAsSort(cloud, 0.2f);
}

TEST(LocalMapVoxel, FarFromTheOriginAndOnEveryCloudSizeTheCentroidsAreTheSortsOwn) {
  // Town coordinates kilometres out, and clouds on both sides of the size where the radix sort takes over.
  for (std::size_t n : {1u, 2u, 255u, 256u, 257u, 5000u}) {
    expectSameAsSort(box(n, {2000.0f, -3500.0f, 40.0f}, {30.0f, 5.0f, 2.0f}, static_cast<unsigned>(n)), 0.4f);
  }
}

TEST(LocalMapVoxel, KeysSpanningTheWholeKeyableRangeSortAsTheReferenceDoes) {
  // Voxels at both ends of +-2^20 (63 key bits, six radix passes), mixed with ordinary ones.
  const float leaf = 0.5f;
  const float edge = static_cast<float>((1 << 20) - 1) * leaf;
  PointCloud cloud = box(2000, {0.0f, 0.0f, 0.0f}, {20.0f, 20.0f, 5.0f}, 7);
  for (float x : {-edge, edge})
    for (float y : {-edge, 3.0f, edge})
      for (float z : {-edge, edge}) cloud.emplace_back(x, y, z);
  expectSameAsSort(cloud, leaf);
}

TEST(LocalMapVoxel, UnkeyableAndNonFinitePointsAreDroppedAsBefore) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  PointCloud cloud = box(1000, {1.0f, 2.0f, 3.0f}, {4.0f, 4.0f, 1.0f}, 3);
  cloud.emplace_back(nan, 0.0f, 0.0f);
  cloud.emplace_back(0.0f, inf, 0.0f);
  cloud.emplace_back(1.0e6f, 0.0f, 0.0f);  // 2.5e6 voxels of 0.4 m: beyond 2^20
  expectSameAsSort(cloud, 0.4f);
  const PointCloud out = detail::voxelDownsample(cloud, 0.4f);
  for (const auto& p : out) EXPECT_TRUE(p.allFinite() && std::abs(p.x()) < 10.0f);
}

TEST(LocalMapVoxel, OneVoxelGivesTheMeanOfItsPoints) {
  const PointCloud cloud{{0.1f, 0.1f, 0.1f}, {0.3f, 0.1f, 0.1f}, {0.2f, 0.3f, 0.2f}};
  const PointCloud out = detail::voxelDownsample(cloud, 1.0f);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_NEAR(out[0].x(), 0.2f, 1e-6f);
  EXPECT_NEAR(out[0].y(), 0.5f / 3.0f, 1e-6f);
  EXPECT_NEAR(out[0].z(), 0.4f / 3.0f, 1e-6f);
  EXPECT_TRUE(detail::voxelDownsample({}, 0.4f).empty());
}

}  // namespace
}  // namespace drover::lidar
