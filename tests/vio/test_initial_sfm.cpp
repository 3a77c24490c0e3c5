// Vision-only SfM of the initialisation window (vio/initial_sfm.hpp) against synthetic ground truth.
#include <gtest/gtest.h>

#include "geometry/so3.hpp"
#include "vio/initial_sfm.hpp"
#include "vio/vio_test_scene.hpp"
#include "support/units.hpp"

namespace drover::vio {
namespace {

using test::makeScene;
using test::Motion;
using test::Scene;
using test::SceneConfig;

using ::drover::test::kDeg;

std::vector<FrameFeatures> featuresOf(const Scene& scene) {
  std::vector<FrameFeatures> out;
  for (const auto& f : scene.frames) out.push_back(f.features);
  return out;
}

Eigen::Isometry3d trueCamera(const Scene& scene, std::size_t k) { return scene.T_world_imu[k] * scene.T_imu_cam; }

void matches(const Scene& scene, std::size_t a, std::size_t b, std::vector<Eigen::Vector2d>& xa,
             std::vector<Eigen::Vector2d>& xb) {
  for (const auto& [id, x] : scene.frames[a].features) {
    const auto it = scene.frames[b].features.find(id);
    if (it == scene.frames[b].features.end()) continue;
    xa.push_back(x);
    xb.push_back(it->second);
  }
}

TEST(InitialSfm, RelativePoseRecoversRotationAndTranslationDirection) {
  const Scene scene = makeScene(SceneConfig{});
  std::vector<Eigen::Vector2d> xa, xb;
  matches(scene, 0, 10, xa, xb);
  Eigen::Isometry3d T_a_b;
  std::string why;
  ASSERT_TRUE(relativePose(xa, xb, SfmConfig{}, T_a_b, why)) << why;
  const Eigen::Isometry3d truth = trueCamera(scene, 0).inverse() * trueCamera(scene, 10);
  EXPECT_LT(geometry::rotationAngle(T_a_b.linear().transpose() * truth.linear()), 0.05 * kDeg);
  EXPECT_NEAR(T_a_b.translation().norm(), 1.0, 1e-9);
  const double direction_error = std::acos(std::min(1.0, T_a_b.translation().dot(truth.translation().normalized())));
  EXPECT_LT(direction_error, 0.2 * kDeg);
}

TEST(InitialSfm, RelativePoseRefusesTooFewCorrespondences) {
  const Scene scene = makeScene(SceneConfig{});
  std::vector<Eigen::Vector2d> xa, xb;
  matches(scene, 0, 10, xa, xb);
  xa.resize(20);
  xb.resize(20);
  Eigen::Isometry3d T_a_b;
  std::string why;
  EXPECT_FALSE(relativePose(xa, xb, SfmConfig{}, T_a_b, why));
  EXPECT_NE(why.find("20 correspondences <= 20"), std::string::npos) << why;
}

TEST(InitialSfm, TriangulationIsExactAndRejectsPointsBehindACamera) {
  Eigen::Isometry3d T0 = Eigen::Isometry3d::Identity(), T1 = Eigen::Isometry3d::Identity();
  T1.linear() = geometry::expSO3(Eigen::Vector3d(0.02, -0.1, 0.03));
  T1.translation() = Eigen::Vector3d(-0.5, 0.1, 0.05);
  const Eigen::Vector3d p(0.7, -0.4, 5.0);
  Eigen::Vector3d estimate;
  ASSERT_TRUE(triangulatePoint(T0, T1, (T0 * p).hnormalized(), (T1 * p).hnormalized(), estimate));
  EXPECT_LT((estimate - p).norm(), 1e-9);
  // The same rays seen from a camera turned around (point behind it) must not triangulate.
  Eigen::Isometry3d T_back = T1;
  T_back.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix() * T1.linear();
  const Eigen::Vector3d q = T_back * p;
  EXPECT_LT(q.z(), 0);
  EXPECT_FALSE(triangulatePoint(T0, T_back, (T0 * p).hnormalized(), q.hnormalized(), estimate));
}

TEST(InitialSfm, RotationCompensatedParallaxIsZeroForPureRotationOnly) {
  SceneConfig rotation;
  rotation.motion = Motion::kRotationOnly;
  // The camera is 10 cm ahead of the IMU, so turning about the IMU still moves the camera by a few cm.
  const Scene turning = makeScene(rotation);
  std::vector<Eigen::Vector2d> xa, xb;
  matches(turning, 0, 10, xa, xb);
  ASSERT_GT(xa.size(), 30u);
  EXPECT_GT(meanParallaxPx(xa, xb, 460), 30);
  EXPECT_LT(rotationCompensatedParallaxPx(xa, xb, 460), 2.0);
  // A pure rotation of exact bearings leaves nothing.
  const Eigen::Matrix3d R = geometry::expSO3(Eigen::Vector3d(0.1, -0.2, 0.05));
  std::vector<Eigen::Vector2d> rotated;
  for (const auto& x : xa) rotated.push_back((R * x.homogeneous()).hnormalized());
  EXPECT_LT(rotationCompensatedParallaxPx(xa, rotated, 460), 1e-9);
  // The walking window keeps most of its parallax.
  const Scene walking = makeScene(SceneConfig{});
  xa.clear();
  xb.clear();
  matches(walking, 0, 10, xa, xb);
  EXPECT_GT(rotationCompensatedParallaxPx(xa, xb, 460), 10);
}

TEST(InitialSfm, GlobalSfmMatchesGroundTruthUpToScale) {
  const Scene scene = makeScene(SceneConfig{});
  const SfmResult sfm = globalSfm(featuresOf(scene), SfmConfig{});
  ASSERT_TRUE(sfm.ok) << sfm.why;
  ASSERT_EQ(sfm.T_l_cam.size(), scene.frames.size());
  EXPECT_LT(sfm.reprojection_px, 1e-3);
  const int last = static_cast<int>(scene.frames.size()) - 1;
  const Eigen::Isometry3d T_l_w = trueCamera(scene, sfm.l).inverse();
  const double scale = (T_l_w * trueCamera(scene, last)).translation().norm();  // metres per SfM unit
  EXPECT_NEAR(sfm.T_l_cam[last].translation().norm(), 1.0, 1e-9);  // gauge held by the adjustment
  for (std::size_t k = 0; k < scene.frames.size(); ++k) {
    const Eigen::Isometry3d truth = T_l_w * trueCamera(scene, k);
    EXPECT_LT(geometry::rotationAngle(sfm.T_l_cam[k].linear().transpose() * truth.linear()), 0.01 * kDeg) << k;
    EXPECT_LT((sfm.T_l_cam[k].translation() * scale - truth.translation()).norm(), 1e-4) << k;
  }
  ASSERT_GT(sfm.points_l.size(), 100u);
  for (const auto& [id, p] : sfm.points_l) {
    EXPECT_LT((p * scale - T_l_w * scene.points_world[id]).norm(), 1e-3) << id;
  }
}

TEST(InitialSfm, StillWindowIsRefusedForParallax) {
  SceneConfig still;
  still.motion = Motion::kStill;
  const SfmResult sfm = globalSfm(featuresOf(makeScene(still)), SfmConfig{});
  EXPECT_FALSE(sfm.ok);
  EXPECT_NE(sfm.why.find("parallax"), std::string::npos) << sfm.why;
  EXPECT_NE(sfm.why.find("< 30.0 px"), std::string::npos) << sfm.why;
}

TEST(InitialSfm, RotationOnlyWindowIsRefused) {
  SceneConfig rotation;
  rotation.motion = Motion::kRotationOnly;
  const SfmResult sfm = globalSfm(featuresOf(makeScene(rotation)), SfmConfig{});
  EXPECT_FALSE(sfm.ok);
  EXPECT_NE(sfm.why.find("rotation without translation"), std::string::npos) << sfm.why;
}

TEST(InitialSfm, TooFewFeaturesAreRefused) {
  SceneConfig sparse;
  sparse.points = 18;
  const SfmResult sfm = globalSfm(featuresOf(makeScene(sparse)), SfmConfig{});
  EXPECT_FALSE(sfm.ok);
  EXPECT_NE(sfm.why.find("too few features"), std::string::npos) << sfm.why;
}

TEST(InitialSfm, ConfigValidationNamesTheBadField) {
  EXPECT_TRUE(SfmConfig{}.validate().empty());
  SfmConfig bad;
  bad.focal_px = 0;
  EXPECT_NE(bad.validate().find("focal_px"), std::string::npos);
  bad = SfmConfig{};
  bad.min_pnp_points = 3;
  EXPECT_NE(bad.validate().find("min_pnp_points"), std::string::npos);
  EXPECT_THROW(globalSfm({}, bad), std::invalid_argument);
}

}  // namespace
}  // namespace drover::vio
