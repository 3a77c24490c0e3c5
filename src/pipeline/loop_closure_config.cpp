// LoopClosureConfig's names and validation, and the shift search's fall-back reach (loop_closure.hpp).
#include <cmath>
#include <numbers>

#include "pipeline/loop_closure.hpp"

namespace drover::pipeline {

const char* toString(LoopSource source) {
  switch (source) {
    case LoopSource::kRadius:
      return "radius";
    case LoopSource::kBoth:
      return "both";
    case LoopSource::kScanContext:
      break;
  }
  return "scancontext";
}

const char* toString(ShiftFallback fallback) {
  switch (fallback) {
    case ShiftFallback::kBudget:
      return "budget";
    case ShiftFallback::kNever:
      return "never";
    case ShiftFallback::kAlways:
      break;
  }
  return "always";
}

std::string LoopClosureConfig::validate() const {
  if (std::string e = database.validate(); !e.empty()) return "database: " + e;
  if (std::string e = verifier.validate(); !e.empty()) return "verifier: " + e;
  if (std::string e = graph.validate(); !e.empty()) return "graph: " + e;
  const double positive[] = {radius, odometry_sigma_position, odometry_sigma_rotation, degenerate_sigma,
                             max_drift_floor, max_rotation_drift_floor};
  for (double v : positive)
    if (!std::isfinite(v) || v <= 0)
      return "radius, odometry_sigma_*, degenerate_sigma, max_drift_floor and max_rotation_drift_floor must be finite "
             "and > 0";
  for (double v : {max_drift_ratio, degenerate_drift, max_rotation_drift_ratio, degenerate_rotation_drift})
    if (!std::isfinite(v) || v < 0)
      return "max_drift_ratio, degenerate_drift, max_rotation_drift_ratio and degenerate_rotation_drift must be "
             "finite and >= 0";
  if (!std::isfinite(min_age) || min_age < 0) return "min_age must be finite and >= 0 s";
  if (!std::isfinite(vis_carried_sigma) || vis_carried_sigma < 0) return "vis_carried_sigma must be finite and >= 0";
  if (shift_fallback != ShiftFallback::kAlways && shift_fallback != ShiftFallback::kBudget &&
      shift_fallback != ShiftFallback::kNever)
    return "shift_fallback must be always, budget or never";
  if (submap_keyframes < 0 || max_verifications < 1 || skip_after_loop < 0)
    return "submap_keyframes and skip_after_loop must be >= 0, max_verifications >= 1";
  if (max_events < 0) return "max_events must be >= 0 (0 keeps every event)";
  return {};
}

int shiftFallbackRadius(const LoopClosureConfig& config, double path, double degenerate_rotation) {
  switch (config.shift_fallback) {
    case ShiftFallback::kAlways:
      return loop::YawPrior::kFullFallback;
    case ShiftFallback::kNever:
      return 0;
    case ShiftFallback::kBudget:
      break;
  }
  const double budget = config.max_rotation_drift_floor + config.max_rotation_drift_ratio * path +
                        config.degenerate_rotation_drift * degenerate_rotation;
  const double sector = 2 * std::numbers::pi / config.database.descriptor.sectors;
  const double reach = std::ceil(budget / sector) + 1;  // + a sector: the descriptor's quantisation
  return reach >= loop::YawPrior::kFullFallback ? loop::YawPrior::kFullFallback : static_cast<int>(reach);
}

}  // namespace drover::pipeline
