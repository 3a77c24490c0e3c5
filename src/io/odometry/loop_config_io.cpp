#include "io/odometry/loop_config_io.hpp"

#include "io/user_values.hpp"

namespace drover::io {

void bindLoopSection(YamlSection& s, pipeline::LoopClosureConfig& c, LoopEnumStrings& e) {
  loop::ScanContextConfig& d = c.database.descriptor;
  loop::LoopVerifierConfig& v = c.verifier;
  s.bind("enabled", c.enabled)
      .bindChoice("source", e.source, {"scancontext", "radius", "both"})
      .bind("yaw_prior", c.yaw_prior)
      .bind("visual_yaw_prior", c.visual_yaw_prior)
      .bindChoice("shift_fallback", e.shift_fallback, {"always", "budget", "never"})
      .bindSeconds("min_age", c.min_age, atLeast(0, "s"))
      .bind("submap_keyframes", c.submap_keyframes)
      .bind("max_verifications", c.max_verifications)
      .bind("skip_after_loop", c.skip_after_loop)
      .bind("radius", c.radius)
      .bind("odometry_sigma_position", c.odometry_sigma_position)
      .bind("odometry_sigma_rotation", c.odometry_sigma_rotation)
      .bind("degenerate_sigma", c.degenerate_sigma)
      .bind("vis_carried_sigma", c.vis_carried_sigma)
      .bind("max_drift_floor", c.max_drift_floor)
      .bind("max_drift_ratio", c.max_drift_ratio)
      .bind("degenerate_drift", c.degenerate_drift)
      .bind("max_rotation_drift_floor", c.max_rotation_drift_floor)
      .bind("max_rotation_drift_ratio", c.max_rotation_drift_ratio)
      .bind("degenerate_rotation_drift", c.degenerate_rotation_drift)
      .bind("keep_retired_nodes", c.keep_retired_nodes)
      .bind("skip_degenerate_places", c.skip_degenerate_places)
      .bind("budget_through_loops", c.budget_through_loops)
      .bind("four_dof_with_imu", c.four_dof_with_imu)
      .bind("max_events", c.max_events)
      .nested("scan_context",
              [&](YamlSection& n) {
                n.bind("rings", d.rings)
                    .bind("sectors", d.sectors)
                    .bind("max_radius", d.max_radius)
                    .bind("sensor_height", d.sensor_height)
                    .bind("auto_height", d.auto_height)
                    .bind("ground_lift", d.ground_lift)
                    .bind("threshold", d.threshold)
                    .bind("search_radius", d.search_radius)
                    .bind("lateral_step", d.lateral_step)
                    .bind("lateral_steps", d.lateral_steps)
                    .bind("candidates", c.database.candidates)
                    .bind("exclude_recent", c.database.exclude_recent);
              })
      .nested("verifier",
              [&](YamlSection& n) {
                n.bind("max_fitness", v.max_fitness)
                    .bind("min_inliers", v.min_inliers)
                    .bind("min_inlier_ratio", v.min_inlier_ratio)
                    .bind("max_correction_translation", v.max_correction_translation)
                    .bind("max_correction_rotation", v.max_correction_rotation)
                    .bind("sigma_floor_position", v.sigma_floor_position)
                    .bind("sigma_floor_rotation", v.sigma_floor_rotation)
                    .bind("sigma_fitness_reference", v.sigma_fitness_reference);
              })
      .nested("graph", [&](YamlSection& n) {
        n.bind("max_iterations", c.graph.max_iterations)
            .bindChoice("loop_loss", e.loop_loss, {"none", "huber", "cauchy"})
            .bind("loop_loss_scale", c.graph.loop_loss_scale);
      });
}

void applyLoopEnums(const LoopEnumStrings& e, pipeline::LoopClosureConfig& c) {
  c.source = e.source == "radius" ? pipeline::LoopSource::kRadius
             : e.source == "both" ? pipeline::LoopSource::kBoth
                                  : pipeline::LoopSource::kScanContext;
  c.graph.loop_loss = backend::parseRobustLoss(e.loop_loss);
  c.shift_fallback = e.shift_fallback == "always"  ? pipeline::ShiftFallback::kAlways
                     : e.shift_fallback == "never" ? pipeline::ShiftFallback::kNever
                                                   : pipeline::ShiftFallback::kBudget;
}

}  // namespace drover::io
