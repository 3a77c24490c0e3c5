// The lidar's depth holds the VIS's metric scale where the IMU cannot: on the downhill course the robot pulls away
// and then holds its speed, so after the first seconds only the features' depths tell the window how far it moved.
// Beside the LIS, with the lidar depths as factors (vio.depth_mode: factor, the drover preset's), the VIS must drift
// about as little as with the depths held fixed (LVI-SAM's mode). A factor whose measurement is the feature's depth
// from the previous solve instead of the lidar's only resists change from one frame to the next: the scale walks,
// and the VIS drifted 4.1 % here (the depths held fixed 1.55 %, no lidar depth 5.8 %).
#include <gtest/gtest.h>

#include <cstdio>

#include "eval/association.hpp"
#include "support/fused_run.hpp"

namespace drover {
namespace {

struct VisDrift {
  double path = 0;       // [m] of the truth over the VIS's estimates
  double end_error = 0;  // [m] after aligning the VIS's first pose on the truth's
};

// The drift as bench/eval_vis.sh measures it (tools/course_report.py on trajectory_vis.tum): the VIS's poses matched
// to the truth's nearest stamps (the truth at 200 Hz, the camera at 15 Hz: at most 2.5 ms apart).
VisDrift visDrift(const test::FusedRun& r, const Trajectory& truth) {
  VisDrift d;
  const eval::Association a = eval::associate(r.vis, truth);
  if (a.size() < 2) return d;
  const StampedPose& vis_first = r.vis[a.first.front()];
  const StampedPose& vis_last = r.vis[a.first.back()];
  const Eigen::Isometry3d T_truth_est = truth[a.second.front()].T_world_body * vis_first.T_world_body.inverse();
  for (std::size_t i = a.second.front() + 1; i <= a.second.back(); ++i)
    d.path += (truth[i].T_world_body.translation() - truth[i - 1].T_world_body.translation()).norm();
  d.end_error = ((T_truth_est * vis_last.T_world_body).translation() -
                 truth[a.second.back()].T_world_body.translation()).norm();
  return d;
}

TEST(SimVisLidarDepth, DepthsAsFactorsHoldTheVisScaleOnAConstantSpeedDescentWithinTwoPercent) {
  const test::LiveCourse course = test::simulateLiveCourse("downhill", 40, 1, true);
  const auto mode = [](vio::DepthMode m) { return [m](vio::VioConfig& c) { c.depth_mode = m; }; };
  const test::FusedRun factor = runFused(course, 0, true, {}, mode(vio::DepthMode::kFactor));
  const VisDrift d = visDrift(factor, course.truth);
  std::printf("downhill, the VIS beside the LIS with lidar depths as factors: %.1f m, end error %.3f m (%.2f %%), "
              "%zu frames, %zu resets\n",
              d.path, d.end_error, 100 * d.end_error / d.path, factor.vis.size(), factor.vis_resets);
  ASSERT_GT(d.path, 25.0) << "the VIS must estimate most of the course";
  EXPECT_EQ(factor.vis_resets, 0u);
  EXPECT_LT(d.end_error / d.path, 0.02);  // measured 1.09 % (the depths held fixed: 1.55 %; that factor 4.11 %)
}

}  // namespace
}  // namespace drover
