#pragma once
// Output of `drover eval`: evo-style text tables, the JSON figures, and the plot (tools/plot_trajectory.py).
#include <nlohmann/json.hpp>
#include <string>

#include "eval/ape.hpp"
#include "eval/kitti_drift.hpp"
#include "eval/rpe.hpp"

namespace drover::cli {

using Json = nlohmann::ordered_json;

// Title lines as evo prints them, e.g. "APE w.r.t. translation part (m)\n(with SE(3) Umeyama alignment)".
std::string apeTitle(const eval::ApeResult& r);
std::string rpeTitle(const eval::RpeResult& r, const eval::RpeOptions& o);

// "       max\t0.123456" ... in evo's order (max, mean, median, min, rmse, sse, std).
std::string statisticsTable(const eval::ErrorStatistics& s);
std::string kittiTable(const eval::KittiDriftResult& r);

// The statistics under the keys max, min, std, median, mean, rmse, sse, plus count.
Json statisticsJson(const eval::ErrorStatistics& s);
// The est -> ref similarity found: rotation (row-major), translation, scale.
Json alignmentJson(const eval::Sim3& transform);
Json kittiJson(const eval::KittiDriftResult& r);

// Data for the plot: errors over time and the trajectories from above.
struct PlotData {
  std::string title;
  std::string unit;
  std::vector<Time> times;                // [ns] one per error
  std::vector<double> errors;
  std::vector<Eigen::Vector3d> est_at_errors;  // aligned estimate position of each error
  std::vector<Eigen::Vector3d> ref_path;       // the matched reference, for context
};

// Errors at the estimate poses est_aligned[k] for k in `at`; the reference path ref[ref_index] for context.
PlotData plotData(const std::string& title, const char* unit, const std::vector<Time>& times,
                  const std::vector<double>& errors, const Trajectory& est_aligned, const std::vector<std::size_t>& at,
                  const Trajectory& ref, const std::vector<std::size_t>& ref_index);

// Runs the plot script to write `png`. Never throws for a missing python3/matplotlib or a failing script:
// returns false after logging one line saying the plot was skipped and why.
bool writePlot(const PlotData& data, const std::string& png);

}  // namespace drover::cli
