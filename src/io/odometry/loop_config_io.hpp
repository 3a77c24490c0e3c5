#pragma once
// The `loop:` section of a platform config -> pipeline::LoopClosureConfig (read by loadOdometryConfig). Keys, all
// optional (left out = the defaults in pipeline/loop_closure.hpp and loop/*.hpp, which give the units):
//   loop: enabled, source (scancontext | radius | both), yaw_prior, visual_yaw_prior, shift_fallback (always | budget | never),
//         min_age [s], submap_keyframes,
//         max_verifications, skip_after_loop, radius [m], odometry_sigma_position [m], odometry_sigma_rotation [rad],
//         degenerate_sigma, vis_carried_sigma, max_drift_floor [m], max_drift_ratio, degenerate_drift [m],
//         max_rotation_drift_floor [rad], max_rotation_drift_ratio [rad/m], degenerate_rotation_drift [rad],
//         keep_retired_nodes, skip_degenerate_places, budget_through_loops, four_dof_with_imu, max_events [events]
//     scan_context: rings, sectors, max_radius [m], sensor_height [m], auto_height, ground_lift [m], threshold,
//                   search_radius [sectors],
//                   lateral_step [m], lateral_steps, candidates, exclude_recent [keyframes]
//     verifier:     max_fitness [m], min_inliers, min_inlier_ratio, max_correction_translation [m],
//                   max_correction_rotation [rad], sigma_floor_position [m], sigma_floor_rotation [rad],
//                   sigma_fitness_reference [m]
//     graph:        max_iterations, loop_loss (none | huber | cauchy), loop_loss_scale
#include <string>

#include "io/yaml_section.hpp"
#include "pipeline/loop_closure.hpp"

namespace drover::io {

// Enumerations travel as strings and are applied by applyLoopEnums after YamlSection::apply.
struct LoopEnumStrings {
  std::string source = "scancontext", loop_loss = "huber", shift_fallback = "budget";
};

void bindLoopSection(YamlSection& s, pipeline::LoopClosureConfig& c, LoopEnumStrings& e);
void applyLoopEnums(const LoopEnumStrings& e, pipeline::LoopClosureConfig& c);

}  // namespace drover::io
