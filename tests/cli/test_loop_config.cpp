// The `loop:` section of a platform config -> pipeline::LoopClosureConfig (io/odometry/loop_config_io.hpp): every
// key reaches its own field, and a mistake is an IoError naming the line and the dotted key.
#include <gtest/gtest.h>

#include <string>

#include "odometry_config_test_util.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test_config::errorOf;
using test_config::has;
using test_config::load;
using pipeline::OdometryConfig;

TEST(LoopConfigReader, TheLoopSectionReachesEveryPartOfTheLoopClosure) {
  test::TempDir dir;
  const OdometryConfig c = load(dir, R"(loop:
  enabled: false
  source: both
  min_age: 12.5
  max_drift_ratio: 0.2
  vis_carried_sigma: 0.2
  max_rotation_drift_floor: 0.3
  max_rotation_drift_ratio: 0.001
  degenerate_rotation_drift: 0.02
  keep_retired_nodes: true
  skip_degenerate_places: true
  budget_through_loops: true
  four_dof_with_imu: true
  max_events: 100
  scan_context:
    sensor_height: 1.5
    auto_height: true
    threshold: 0.2
    search_radius: 4
    candidates: 7
    exclude_recent: 20
  verifier:
    max_fitness: 0.3
    min_inliers: 50
    sigma_fitness_reference: 0.07
  graph:
    loop_loss: cauchy
    loop_loss_scale: 2.0
odometry:
  matcher:
    max_iterations: 17
)");
  EXPECT_FALSE(c.loop.enabled);
  EXPECT_EQ(c.loop.source, pipeline::LoopSource::kBoth);
  EXPECT_EQ(c.loop.min_age, 12.5);
  EXPECT_EQ(c.loop.max_drift_ratio, 0.2);
  EXPECT_EQ(c.loop.vis_carried_sigma, 0.2);
  EXPECT_EQ(c.loop.max_rotation_drift_floor, 0.3);
  EXPECT_EQ(c.loop.max_rotation_drift_ratio, 0.001);
  EXPECT_EQ(c.loop.degenerate_rotation_drift, 0.02);
  EXPECT_TRUE(c.loop.keep_retired_nodes);
  EXPECT_TRUE(c.loop.skip_degenerate_places);
  EXPECT_TRUE(c.loop.budget_through_loops);
  EXPECT_TRUE(c.loop.four_dof_with_imu);
  EXPECT_TRUE(c.loopClosure().graph.yaw_only_rotation);
  EXPECT_EQ(c.loop.max_events, 100);
  EXPECT_EQ(c.loop.database.descriptor.sensor_height, 1.5);
  EXPECT_TRUE(c.loop.database.descriptor.auto_height);
  EXPECT_EQ(c.loop.database.descriptor.threshold, 0.2);
  EXPECT_EQ(c.loop.database.descriptor.search_radius, 4);
  EXPECT_EQ(c.loop.database.candidates, 7);
  EXPECT_EQ(c.loop.database.exclude_recent, 20);
  EXPECT_EQ(c.loop.verifier.max_fitness, 0.3);
  EXPECT_EQ(c.loop.verifier.min_inliers, 50);
  EXPECT_EQ(c.loop.verifier.sigma_fitness_reference, 0.07);
  EXPECT_EQ(c.loop.graph.loop_loss, backend::RobustLoss::kCauchy);
  EXPECT_EQ(c.loop.graph.loop_loss_scale, 2.0);
  EXPECT_EQ(c.loop.verifier.matcher.max_iterations, 17);  // the verifier matches as the odometry does
}

TEST(LoopConfigReader, TheLoopGraphIsFourDofOnlyWhenAskedAndTheImuIsFused) {
  test::TempDir dir;
  EXPECT_FALSE(load(dir, "loop:\n  enabled: true\n").loopClosure().graph.yaw_only_rotation);  // the default
  EXPECT_TRUE(load(dir, "loop:\n  four_dof_with_imu: true\n").loopClosure().graph.yaw_only_rotation);
  EXPECT_FALSE(load(dir, "odometry:\n  use_imu: false\nloop:\n  four_dof_with_imu: true\n")
                   .loopClosure()
                   .graph.yaw_only_rotation);
}

TEST(LoopConfigReader, TheShiftFallBackIsTheBudgetsByDefaultAndTheOldFullSearchOnRequest) {
  test::TempDir dir;
  EXPECT_EQ(load(dir, "loop:\n  enabled: true\n").loop.shift_fallback, pipeline::ShiftFallback::kBudget);
  EXPECT_EQ(load(dir, "loop:\n  shift_fallback: always\n").loop.shift_fallback, pipeline::ShiftFallback::kAlways);
  EXPECT_EQ(load(dir, "loop:\n  shift_fallback: never\n").loop.shift_fallback, pipeline::ShiftFallback::kNever);
  const std::string e = errorOf(dir, "loop:\n  shift_fallback: full\n");
  EXPECT_TRUE(has(e, "line 2") && has(e, "loop.shift_fallback") && has(e, "budget")) << e;
}

TEST(LoopConfigReader, AnUnknownLoopKeyOrSourceNamesItsLineAndKey) {
  test::TempDir dir;
  std::string e = errorOf(dir, "loop:\n  scan_context:\n    rings: 20\n    ring: 20\n");
  EXPECT_TRUE(has(e, "line 4") && has(e, "loop.scan_context.ring")) << e;
  e = errorOf(dir, "loop:\n  source: scan-context\n");
  EXPECT_TRUE(has(e, "line 2") && has(e, "loop.source") && has(e, "scancontext")) << e;
  e = errorOf(dir, "loop:\n  scan_context:\n    threshold: 5\n");
  EXPECT_TRUE(has(e, "threshold")) << e;
  e = errorOf(dir, "loop:\n  max_events: -1\n");
  EXPECT_TRUE(has(e, "max_events")) << e;
  e = errorOf(dir, "loop:\n  verifier:\n    sigma_fitness_reference: -0.05\n");
  EXPECT_TRUE(has(e, "sigma_fitness_reference")) << e;
  e = errorOf(dir, "loop:\n  vis_carried_sigma: -0.1\n");
  EXPECT_TRUE(has(e, "vis_carried_sigma")) << e;
}

}  // namespace
}  // namespace drover::io
