// The camera as an independent judge of the KITTI reference poses (issue 4). On the real snippets in ../shared
// (sequences 00 and 05, frames 0-9) camera 2 alone, with metric depth from the lidar, estimates the motion from
// frame 0 to frame 9 (method: support/kitti_camera_motion.hpp), and that estimate is held against the official poses
// and the lidar odometry (config/kitti.yaml, run as test_kitti_lidar_odometry runs it). Everything is compared in the
// camera-2 frame.
//
// Why: the lidar odometry meets issue 4's bound on 05 but is 14 % short of the reference on 00, whose first 14
// reference poses are a constant-velocity extrapolation (see test_kitti_lidar_odometry). On 05 the camera must agree
// with the reference: that validates the method. On 00 it must agree with the lidar, and so be at least 10 % short of
// the reference and rotate about 1 deg more: two sensors, matched by unrelated methods, then say that the reference
// is what is wrong there. (The camera's scale does come from the lidar's ranges, though not from its scan matching;
// its rotation uses no lidar at all.)
//
// The bounds come from the measurements: each is stated beside the value measured with the settings here and the
// range seen while varying them (PnP threshold 1-3 px, forward-backward limit 0.5-1 px, depth spread 0.15-2 m,
// spherical grid 0.1-0.5 deg, 3000-8000 corners 3-7 px apart). What was found: on 05 the camera is within 1.2 % of
// the reference (length -0.4 %; the rest is a 0.6 deg difference in the direction of travel, the camera's being less
// upward), its rotation within 0.02 deg; on 00 it travels 6.74 m where the reference has 7.74 m and the lidar 6.68 m,
// and turns 2.19 deg where the reference has 1.25 deg and the lidar 2.26 deg.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "geometry/so3.hpp"
#include "support/kitti_camera_motion.hpp"
#include "support/kitti_lidar_snippet.hpp"
#include "support/shared_data.hpp"

namespace drover {
namespace {

using test::kSnippetFrames;

double deg(double rad) { return rad * 180.0 / std::numbers::pi; }
double angleDeg(const Eigen::Matrix3d& R) { return deg(geometry::rotationAngle(R)); }

// A lidar-frame trajectory's motion from frame 0 to frame 9 and its travelled distance, in the camera-2 frame.
struct Motion {
  Eigen::Isometry3d T_cam0_cam9 = Eigen::Isometry3d::Identity();
  double travelled = 0;  // [m] sum of the nine steps' lengths
};

Motion inCameraFrame(const Trajectory& T_world_lidar, const Eigen::Isometry3d& T_lidar_cam) {
  const auto relative = [&](std::size_t a, std::size_t b) {
    return T_lidar_cam.inverse() * T_world_lidar[a].T_world_body.inverse() * T_world_lidar[b].T_world_body *
           T_lidar_cam;
  };
  Motion m;
  for (std::size_t i = 1; i < kSnippetFrames; ++i) m.travelled += relative(i - 1, i).translation().norm();
  m.T_cam0_cam9 = relative(0, kSnippetFrames - 1);
  return m;
}

// Estimate a against estimate b.
struct Comparison {
  double translation = 0;  // |t_a - t_b| / |t_b|
  double length = 0;       // |t_a| / |t_b| - 1
  double direction = 0;    // [deg] between t_a and t_b
};

Comparison compare(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return {(a - b).norm() / b.norm(), a.norm() / b.norm() - 1, deg(std::atan2(a.cross(b).norm(), a.dot(b)))};
}

void print(const char* what, const Comparison& c) {
  std::printf("  %-28s translation %5.2f %% (length %+6.2f %%, direction %.2f deg)\n", what, 100 * c.translation,
              100 * c.length, c.direction);
}

struct CrossCheck {
  test::CameraMotion camera;
  Motion reference, lidar;
  Comparison camera_vs_reference, camera_vs_lidar, chained_vs_direct;
  double rotation_vs_reference = 0, rotation_vs_lidar = 0;  // [deg] of the camera's (essential) rotation
};

CrossCheck crossCheck(const std::string& sequence) {
  const test::CameraSnippet s = test::loadCameraSnippet(sequence);
  EXPECT_EQ(s.grey.size(), static_cast<std::size_t>(kSnippetFrames));
  EXPECT_EQ(s.scans.size(), static_cast<std::size_t>(kSnippetFrames));
  const test::KittiLidarSnippet lidar = test::runKittiLidarSnippet(sequence);
  EXPECT_EQ(lidar.estimate.size(), static_cast<std::size_t>(kSnippetFrames));
  EXPECT_GE(s.truth.size(), static_cast<std::size_t>(kSnippetFrames));
  CrossCheck c;
  if (s.grey.size() != kSnippetFrames || s.scans.size() != kSnippetFrames || lidar.estimate.size() != kSnippetFrames ||
      s.truth.size() < kSnippetFrames)
    return c;
  c.camera = test::estimateCameraMotion(s);
  c.reference = inCameraFrame(s.truth, s.T_lidar_cam);
  c.lidar = inCameraFrame(lidar.estimate, s.T_lidar_cam);
  const test::CameraMotion& m = c.camera;
  const Eigen::Vector3d t_camera = m.chained.translation(), t_reference = c.reference.T_cam0_cam9.translation(),
                        t_lidar = c.lidar.T_cam0_cam9.translation();
  c.camera_vs_reference = compare(t_camera, t_reference);
  c.camera_vs_lidar = compare(t_camera, t_lidar);
  c.chained_vs_direct = compare(t_camera, m.direct.translation());
  c.rotation_vs_reference = angleDeg(c.reference.T_cam0_cam9.linear().transpose() * m.rotation);
  c.rotation_vs_lidar = angleDeg(c.lidar.T_cam0_cam9.linear().transpose() * m.rotation);

  std::printf("KITTI %s, camera 2, frame 0 -> 9\n", sequence.c_str());
  std::printf("  travelled: camera %.3f m, reference %.3f m, lidar %.3f m\n", m.travelled, c.reference.travelled,
              c.lidar.travelled);
  std::printf("  |t 0->9|: camera chained %.3f m, direct %.3f m, reference %.3f m, lidar %.3f m\n", t_camera.norm(),
              m.direct.translation().norm(), t_reference.norm(), t_lidar.norm());
  std::printf("  rotation: camera %.3f deg (PnP chained %.3f, direct %.3f), reference %.3f deg, lidar %.3f deg\n",
              angleDeg(m.rotation), angleDeg(m.chained.linear()), angleDeg(m.direct.linear()),
              angleDeg(c.reference.T_cam0_cam9.linear()), angleDeg(c.lidar.T_cam0_cam9.linear()));
  print("camera vs reference", c.camera_vs_reference);
  print("camera vs lidar", c.camera_vs_lidar);
  print("lidar vs reference", compare(t_lidar, t_reference));
  print("camera chained vs direct", c.chained_vs_direct);
  std::printf("  camera rotation vs reference %.3f deg, vs lidar %.3f deg; lidar vs reference %.3f deg\n",
              c.rotation_vs_reference, c.rotation_vs_lidar,
              angleDeg(c.reference.T_cam0_cam9.linear().transpose() * c.lidar.T_cam0_cam9.linear()));
  std::printf(
      "  corners with depth >= %d a frame; PnP inliers >= %d a step, direct 0 -> 9 %d of %d tracked; "
      "essential inliers >= %d a step\n",
      m.fewest_depth_features, m.fewest_step_inliers, m.direct_inliers, m.direct_tracked, m.fewest_essential_inliers);

  // The estimate rests on many points (measured on 05 / 00: 371 / 408 PnP inliers a step, 77 / 43 direct, 2238 /
  // 3096 essential inliers a step).
  EXPECT_GE(m.fewest_step_inliers, 200) << sequence;
  EXPECT_GE(m.direct_inliers, 25) << sequence;
  EXPECT_GE(m.fewest_essential_inliers, 1000) << sequence;
  // No bias per step: the chain and the single long PnP agree on the length (measured -0.7 % / +0.0 %; up to 1.3 %
  // apart over the variations). A lidar-camera time offset of 2 ms would put them ~2 % apart.
  EXPECT_LT(std::abs(c.chained_vs_direct.length), 0.02) << sequence;
  return c;
}

TEST(KittiCameraCrossCheck, Sequence05CameraAgreesWithTheReferenceWithinOnePointFivePercentAndATenthOfADegree) {
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/05/image_2/000009.png"));
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/05/velodyne/000009.bin"));
  const CrossCheck c = crossCheck("05");
  // Measured 1.17 % (1.10-1.38 % over the variations), length -0.40 % (-0.32 to -0.66 %), direction 0.63 deg
  // (0.58-0.70 deg), rotation 0.018 deg (0.018-0.057 deg).
  EXPECT_LE(c.camera_vs_reference.translation, 0.015);
  EXPECT_LE(std::abs(c.camera_vs_reference.length), 0.01);
  EXPECT_LE(c.camera_vs_reference.direction, 1.0);
  EXPECT_LE(c.rotation_vs_reference, 0.15);
}

TEST(KittiCameraCrossCheck, Sequence00CameraAgreesWithTheLidarAndNotWithTheReference) {
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/00/image_2/000009.png"));
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/00/velodyne/000009.bin"));
  const CrossCheck c = crossCheck("00");
  // With the lidar: measured 1.09 % (0.78-1.23 % over the variations), length +0.90 % (+0.19 to +1.09 %), rotation
  // 0.16 deg (0.16-0.19 deg): as close as issue 4 asks of the lidar against a reference.
  EXPECT_LE(c.camera_vs_lidar.translation, 0.015);
  EXPECT_LE(std::abs(c.camera_vs_lidar.length), 0.015);
  EXPECT_LE(c.rotation_vs_lidar, 0.3);
  // Not with the reference: the camera travels 0.871 of the reference's distance (0.868-0.873), and its rotation is
  // 1.19 deg (1.18-1.23 deg) from the reference's. When the reference is corrected, these fail: then revisit the 00
  // bounds of test_kitti_lidar_odometry.
  EXPECT_LE(c.camera.travelled, 0.90 * c.reference.travelled);
  EXPECT_GE(c.rotation_vs_reference, 0.8);
}

}  // namespace
}  // namespace drover
