// The window's feature bookkeeping: parallax, anchors, exact triangulation, and what sliding does to anchors and
// depths (VINS-Mono's FeatureManager).
#include <gtest/gtest.h>

#include "vio/feature_manager.hpp"

namespace drover::vio {
namespace {

FrameFeature feature(std::uint64_t id, double x, double y, double lidar_depth = 0) {
  FrameFeature f;
  f.id = id;
  f.normalized = {x, y};
  f.lidar_depth = lidar_depth;
  return f;
}

Eigen::Isometry3d cameraAt(double x) {  // cameras along the world x axis, looking along world z
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, 0, 0);
  return T;
}

TEST(FeatureManager, ParallaxIsTheMeanShiftBetweenTheTwoPreviousFrames) {
  FeatureManager m;
  EXPECT_LT(m.addFrame(0, {feature(1, 0, 0), feature(2, 0.1, 0)}, 0), 0);
  EXPECT_LT(m.addFrame(1, {feature(1, 0.01, 0), feature(2, 0.13, 0)}, 0), 0);
  // frames 0 and 1: shifts 0.01 and 0.03 -> mean 0.02
  EXPECT_NEAR(m.addFrame(2, {feature(1, 0.02, 0)}, 0), 0.02, 1e-12);
  EXPECT_EQ(m.lastTracked(), 1);
}

TEST(FeatureManager, TriangulatesAPointExactlyFromThreeViews) {
  FeatureManager m;
  const Eigen::Vector3d p(0.4, -0.2, 5.0);  // world = anchor camera
  std::vector<Eigen::Isometry3d> cams;
  for (int k = 0; k < 3; ++k) {
    cams.push_back(cameraAt(0.3 * k));
    const Eigen::Vector3d pc = cams.back().inverse() * p;
    m.addFrame(k, {feature(7, pc.x() / pc.z(), pc.y() / pc.z())}, 0);
  }
  m.initializeDepths(cams, false);
  EXPECT_NEAR(m.features().at(7).depth, 5.0, 1e-9);
}

TEST(FeatureManager, TakesTheAnchorsLidarDepthWhenAllowed) {
  FeatureManager m;
  m.addFrame(0, {feature(1, 0, 0, 7.5)}, 0);
  m.addFrame(1, {feature(1, -0.02, 0)}, 0);
  m.initializeDepths({cameraAt(0), cameraAt(0.1)}, true);
  EXPECT_DOUBLE_EQ(m.features().at(1).depth, 7.5);
  EXPECT_TRUE(m.features().at(1).lidar_anchor);
}

TEST(FeatureManager, RemovingTheOldestFrameReexpressesTheDepthInTheNewAnchor) {
  FeatureManager m;
  const Eigen::Vector3d p(0.5, 0.1, 4.0);
  std::vector<Eigen::Isometry3d> cams = {cameraAt(0), cameraAt(0.5)};
  cams[1].translation().z() = 1.0;  // the second camera is 1 m closer
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d pc = cams[static_cast<std::size_t>(k)].inverse() * p;
    m.addFrame(k, {feature(3, pc.x() / pc.z(), pc.y() / pc.z()), feature(4, 0.2, 0.2)}, 0);
  }
  m.features().at(3).depth = 4.0;
  m.addFrame(2, {feature(3, 0, 0)}, 0);  // feature 4 ends at frame 1
  m.removeOldest(cams[0], cams[1], false);
  ASSERT_EQ(m.features().count(3), 1u);
  EXPECT_NEAR(m.features().at(3).depth, 3.0, 1e-12);
  EXPECT_EQ(m.features().at(3).start(), 0);
  EXPECT_EQ(m.features().at(3).end(), 1);
  ASSERT_EQ(m.features().count(4), 1u);  // seen in (old) frame 1 only now: kept, anchored at 0
  EXPECT_EQ(m.features().at(4).obs.size(), 1u);
}

TEST(FeatureManager, RemovingTheSecondNewestKeepsTracksAndReindexesTheNewest) {
  FeatureManager m;
  m.addFrame(0, {feature(1, 0, 0)}, 0);
  m.addFrame(1, {feature(1, 0, 0), feature(2, 0.1, 0)}, 0);
  m.addFrame(2, {feature(1, 0, 0), feature(2, 0.1, 0), feature(3, 0.2, 0)}, 0);
  m.removeSecondNewest(2);
  EXPECT_EQ(m.features().at(1).obs.size(), 2u);
  EXPECT_EQ(m.features().at(1).end(), 1);
  EXPECT_EQ(m.features().at(2).start(), 1);  // its anchor (frame 1) left: the newest is its anchor now
  EXPECT_EQ(m.features().at(2).obs.size(), 1u);
  EXPECT_EQ(m.features().at(3).start(), 1);
}

TEST(FeatureManager, UsableNeedsTwoObservationsAndAnAnchorBeforeTheSecondNewest) {
  FeatureManager m;
  for (int k = 0; k < 4; ++k) m.addFrame(k, {feature(1, 0, 0), feature(static_cast<std::uint64_t>(10 + k), 0, 0)}, 0);
  m.addFrame(4, {feature(1, 0, 0), feature(13, 0, 0)}, 0);
  EXPECT_TRUE(m.usable(m.features().at(1), 4, 2));
  EXPECT_FALSE(m.usable(m.features().at(10), 4, 2));  // one observation
  EXPECT_FALSE(m.usable(m.features().at(13), 4, 2));  // anchored at the second-newest frame
}

TEST(FeatureManager, AnOutlierAtTheAnchorMovesTheAnchorAndForgetsTheDepth) {
  FeatureManager m;
  m.addFrame(0, {feature(1, 0, 0)}, 0);
  m.addFrame(1, {feature(1, 0, 0)}, 0);
  m.addFrame(2, {feature(1, 0, 0)}, 0);
  m.features().at(1).depth = 3;
  m.removeObservation(1, 0);
  EXPECT_EQ(m.features().at(1).start(), 1);
  EXPECT_EQ(m.features().at(1).depth, 0);
  m.removeObservation(1, 1);
  m.removeObservation(1, 2);
  EXPECT_EQ(m.features().count(1), 0u);
}

}  // namespace
}  // namespace drover::vio
