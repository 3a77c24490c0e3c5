// KeyframePolicy: LIO-SAM's keyframe thresholds on the motion since the last keyframe.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "geometry/so3.hpp"
#include "lidar/keyframe_policy.hpp"

namespace drover::lidar {
namespace {

Eigen::Isometry3d pose(const Eigen::Vector3d& t, const Eigen::Vector3d& phi) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = geometry::expSO3(phi);
  T.translation() = t;
  return T;
}

// The last keyframe sits away from the origin and turned, so a policy that compared world poses would fail.
const Eigen::Isometry3d kLastKeyframe = pose({100.0, -20.0, 3.0}, {0.1, -0.2, 1.5});

TEST(KeyframePolicy, DefaultsAreLioSamThresholds) {
  const KeyframePolicyConfig config;
  EXPECT_DOUBLE_EQ(config.distance, 1.0);
  EXPECT_DOUBLE_EQ(config.angle, 0.2);
}

TEST(KeyframePolicy, TranslationReachingTheDistanceMakesAKeyframe) {
  const KeyframePolicy policy;
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 2.0, -0.5).normalized();
  const auto below = policy.decide(kLastKeyframe, kLastKeyframe * pose(0.99 * direction, Eigen::Vector3d::Zero()));
  EXPECT_FALSE(below.is_keyframe);
  EXPECT_NEAR(below.distance, 0.99, 1e-12);
  EXPECT_NEAR(below.angle, 0.0, 1e-12);
  const auto above = policy.decide(kLastKeyframe, kLastKeyframe * pose(1.01 * direction, Eigen::Vector3d::Zero()));
  EXPECT_TRUE(above.is_keyframe);
  EXPECT_NEAR(above.distance, 1.01, 1e-12);
}

TEST(KeyframePolicy, RotationReachingTheAngleMakesAKeyframeAboutAnyAxis) {
  const KeyframePolicy policy;
  const Eigen::Vector3d axes[] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                  Eigen::Vector3d(1.0, 1.0, 1.0).normalized()};
  for (const Eigen::Vector3d& axis : axes) {
    const auto below = policy.decide(kLastKeyframe, kLastKeyframe * pose(Eigen::Vector3d::Zero(), 0.19 * axis));
    EXPECT_FALSE(below.is_keyframe);
    EXPECT_NEAR(below.angle, 0.19, 1e-9);
    EXPECT_TRUE(policy.isKeyframe(kLastKeyframe, kLastKeyframe * pose(Eigen::Vector3d::Zero(), 0.21 * axis)));
  }
}

TEST(KeyframePolicy, SmallMotionInBothIsNotAKeyframe) {
  const KeyframePolicy policy({.distance = 2.0, .angle = 0.5});
  EXPECT_FALSE(policy.isKeyframe(kLastKeyframe, kLastKeyframe * pose({1.5, 0.5, 0.0}, {0.0, 0.0, 0.45})));
  EXPECT_TRUE(policy.isKeyframe(kLastKeyframe, kLastKeyframe * pose({2.0, 0.1, 0.0}, {0.0, 0.0, 0.1})));
}

TEST(KeyframePolicy, RejectsBadConfigAndNonFinitePoses) {
  EXPECT_THROW(KeyframePolicy({.distance = 0.0, .angle = 0.2}), std::invalid_argument);
  EXPECT_THROW(KeyframePolicy({.distance = 1.0, .angle = -0.1}), std::invalid_argument);
  EXPECT_THROW(KeyframePolicy({.distance = std::nan(""), .angle = 0.2}), std::invalid_argument);
  const KeyframePolicy policy;
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(policy.decide(kLastKeyframe, bad), std::invalid_argument);
}

}  // namespace
}  // namespace drover::lidar
