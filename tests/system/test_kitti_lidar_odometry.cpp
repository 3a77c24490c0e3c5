// Lidar-only odometry on the real KITTI snippets in ../shared (sequences 00 and 05, the first 10 scans each), with
// the shipped config/kitti.yaml: over the 9 steps the end-to-end relative pose must be within 1.5 % of the
// distance travelled and 0.5 deg of the ground truth (issue 4), and every step must match.
//
// Sequence 00 is the exception, and the reason is the reference, not the odometry: the official poses of its first
// 14 frames are a constant-velocity extrapolation (steps alternate between 0.8587 and 0.8577 m to the tenth of a
// millimetre, then start to vary smoothly at frame 14), while the scans themselves show the car accelerating: edges
// alone, planes alone and point-to-plane on the full clouds all put scan 1 at 0.68 m from scan 0 from any starting
// guess (0 to 1 m), and 05, whose reference does vary, meets the bound. The camera agrees with the lidar, not with
// the reference: test_kitti_camera_crosscheck estimates camera 2's motion from its own images (PnP on lidar depth,
// essential matrices for the rotation), finds it within 1.2 % / 0.02 deg of the reference on 05, and on 00 within
// 1.1 % / 0.16 deg of this lidar odometry -- issue 4's bounds, held there against the camera -- while 13 % / 1.2 deg
// from the reference. Here, the 00 test checks that the reference still has that flat start (so the exception cannot
// outlive the data) and holds the estimate to the bounds that the mismatch allows (14 % and 1.5 deg).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "geometry/so3.hpp"
#include "io/dataset.hpp"
#include "support/kitti_lidar_snippet.hpp"
#include "support/shared_data.hpp"

namespace drover {
namespace {

double poseAngleDeg(const Eigen::Isometry3d& T) { return geometry::rotationAngle(T.linear()) * 180.0 / std::numbers::pi; }

void expectWithinBounds(const std::string& sequence, double max_relative_translation, double max_rotation_deg,
                        double max_step_translation, double max_step_rotation_deg) {
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/" + sequence + "/velodyne/000009.bin"));
  const test::KittiLidarSnippet r = test::runKittiLidarSnippet(sequence);
  ASSERT_EQ(r.estimate.size(), 10u);
  ASSERT_EQ(r.truth.size(), 10u);
  EXPECT_EQ(r.stats.not_converged, 0u);
  double travelled = 0;
  for (std::size_t i = 1; i < 10; ++i) {
    const Eigen::Isometry3d gt = r.truth[i - 1].T_world_body.inverse() * r.truth[i].T_world_body;
    const Eigen::Isometry3d est = r.estimate[i - 1].T_world_body.inverse() * r.estimate[i].T_world_body;
    travelled += gt.translation().norm();
    // Each step: within 10 cm and 0.3 deg (a wrong step could hide in a good end-to-end figure).
    EXPECT_LT((est.translation() - gt.translation()).norm(), max_step_translation) << sequence << " step " << i;
    EXPECT_LT(poseAngleDeg(gt.inverse() * est), max_step_rotation_deg) << sequence << " step " << i;
  }
  const Eigen::Isometry3d gt = r.truth.front().T_world_body.inverse() * r.truth.back().T_world_body;
  const Eigen::Isometry3d est = r.estimate.front().T_world_body.inverse() * r.estimate.back().T_world_body;
  const double t_err = (est.translation() - gt.translation()).norm();
  const double r_err = poseAngleDeg(gt.inverse() * est);
  std::printf("KITTI %s: %.2f m travelled over 9 steps, translation error %.3f m (%.2f %%), rotation %.3f deg\n",
              sequence.c_str(), travelled, t_err, 100.0 * t_err / travelled, r_err);
  ASSERT_GT(travelled, 1.0) << "the snippet must move for the bound to mean anything";
  EXPECT_LE(t_err / travelled, max_relative_translation) << sequence;
  EXPECT_LE(r_err, max_rotation_deg) << sequence;
}

TEST(KittiLidarOdometry, Sequence05SnippetStaysWithinOnePointFivePercentAndHalfADegree) {
  expectWithinBounds("05", 0.015, 0.5, 0.05, 0.1);
}

TEST(KittiLidarOdometry, Sequence00ReferenceStartsWithAConstantVelocityExtrapolation) {
  DROVER_REQUIRE_SHARED(test::sharedData("kitti/sequences/00/poses.txt"));
  io::DatasetOptions options;
  options.load_images = options.load_lidar = false;
  options.kitti_max_frames = 15;
  const Trajectory gt =
      io::openDataset(test::sharedData("kitti/sequences/00").string(), "kitti", options)->groundTruth().poses;
  ASSERT_GE(gt.size(), 15u);
  for (std::size_t i = 1; i < 14; ++i) {
    const double step = (gt[i].T_world_body.translation() - gt[i - 1].T_world_body.translation()).norm();
    EXPECT_NEAR(step, 0.8587, 0.002) << "frame " << i << ": the 00 reference changed; revisit the 00 bounds";
  }
}

TEST(KittiLidarOdometry, Sequence00SnippetStaysWithinTheBoundsItsFlatReferenceAllows) {
  expectWithinBounds("00", 0.14, 1.5, 0.20, 0.3);
}

}  // namespace
}  // namespace drover
