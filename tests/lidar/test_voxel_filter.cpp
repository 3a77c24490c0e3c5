// Voxel downsampling: centroids of hand-built clouds, floor semantics at negative coordinates, agreement with a
// brute-force reference, first-seen output order and determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "lidar/voxel_filter.hpp"

namespace drover::lidar {
namespace {

TEST(VoxelFilter, ReplacesEachOccupiedVoxelByTheCentroidOfItsPoints) {
  const PointCloud cloud = {{0.1f, 0.1f, 0.1f}, {2.5f, 0.5f, 0.5f}, {0.3f, 0.5f, 0.9f}, {-0.5f, 0.2f, 0.2f},
                            {0.5f, 0.9f, 0.5f}};
  const PointCloud out = voxelDownsample(cloud, 1.0f);
  ASSERT_EQ(out.size(), 3u);
  // First-seen order: voxel (0,0,0), then (2,0,0), then (-1,0,0).
  EXPECT_TRUE(out[0].isApprox(Eigen::Vector3f(0.3f, 0.5f, 0.5f), 1e-6f)) << out[0].transpose();
  EXPECT_TRUE(out[1].isApprox(Eigen::Vector3f(2.5f, 0.5f, 0.5f), 1e-6f));
  EXPECT_TRUE(out[2].isApprox(Eigen::Vector3f(-0.5f, 0.2f, 0.2f), 1e-6f));
}

TEST(VoxelFilter, PointsEitherSideOfZeroFallInDifferentVoxels) {
  const PointCloud out = voxelDownsample({{-0.01f, 0, 0}, {0.01f, 0, 0}, {0.02f, 0.3f, -0.02f}}, 0.4f);
  ASSERT_EQ(out.size(), 3u);  // x = -0.01 is voxel -1; z = -0.02 is voxel -1 too
  EXPECT_EQ(voxelDownsample({{0.01f, 0, 0}, {0.39f, 0.39f, 0.39f}}, 0.4f).size(), 1u);
}

// Reference: group by exhaustive search over the voxels seen so far.
PointCloud bruteForce(const PointCloud& cloud, float leaf) {
  std::vector<Eigen::Vector3i> keys;
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  for (const Eigen::Vector3f& p : cloud) {
    const Eigen::Vector3i key = (p.cast<double>() / double(leaf)).array().floor().cast<int>();
    std::size_t k = 0;
    while (k < keys.size() && keys[k] != key) ++k;
    if (k == keys.size()) {
      keys.push_back(key);
      sums.push_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    sums[k] += p.cast<double>();
    ++counts[k];
  }
  PointCloud out;
  for (std::size_t k = 0; k < keys.size(); ++k) out.push_back((sums[k] / counts[k]).cast<float>());
  return out;
}

PointCloud randomCloud(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  PointCloud cloud(n);
  for (Eigen::Vector3f& p : cloud) p = Eigen::Vector3f(u(rng), u(rng), 0.2f * u(rng));
  return cloud;
}

TEST(VoxelFilter, AgreesWithABruteForceReferenceInValueAndOrder) {
  const PointCloud cloud = randomCloud(3000, 7);
  const PointCloud out = voxelDownsample(cloud, 0.5f);
  const PointCloud ref = bruteForce(cloud, 0.5f);
  ASSERT_EQ(out.size(), ref.size());
  ASSERT_LT(out.size(), cloud.size());
  for (std::size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(out[i].isApprox(ref[i], 1e-6f)) << i;
}

TEST(VoxelFilter, IsDeterministic) {
  const PointCloud cloud = randomCloud(20000, 3);
  const PointCloud a = voxelDownsample(cloud, 0.3f), b = voxelDownsample(cloud, 0.3f);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]);
}

TEST(VoxelFilter, SkipsNonFinitePointsAndHandlesEmptyClouds) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const PointCloud out = voxelDownsample({{nan, 0, 0}, {1, 1, 1}, {0, std::numeric_limits<float>::infinity(), 0}}, 1);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], Eigen::Vector3f(1, 1, 1));
  EXPECT_TRUE(voxelDownsample({}, 0.4f).empty());
}

TEST(VoxelFilter, RejectsANonPositiveOrNonFiniteLeaf) {
  const PointCloud cloud = {{1, 2, 3}};
  EXPECT_THROW(voxelDownsample(cloud, 0.0f), std::invalid_argument);
  EXPECT_THROW(voxelDownsample(cloud, -1.0f), std::invalid_argument);
  EXPECT_THROW(voxelDownsample(cloud, std::numeric_limits<float>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace drover::lidar
