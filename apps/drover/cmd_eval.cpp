// drover eval: trajectory accuracy against ground truth, with evo's definitions (APE, RPE) and the KITTI
// odometry devkit's segment drift. The maths is in src/eval; this file reads the files, prints and writes.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "apps/drover/eval_report.hpp"
#include "io/output_paths.hpp"
#include "io/trajectory_io.hpp"
#include "io/user_values.hpp"

namespace drover::cli {
namespace {

struct CommonOptions {
  std::string ref, est;
  std::string format = "tum";
  std::string align = "none";
  double t_max_diff = 0.01;  // [s]
  double t_offset = 0.0;     // [s]
  std::string relation = "trans";
  std::string ref_times, est_times;
  std::string plot, json;
};

struct RpeCliOptions {
  CommonOptions common;
  double delta = 1.0;
  std::string delta_unit = "frames";
  bool pairs_from_reference = false;
};

eval::Alignment parseAlignment(const std::string& s) {
  if (s == "se3") return eval::Alignment::kSe3;
  if (s == "sim3") return eval::Alignment::kSim3;
  return eval::Alignment::kNone;
}

eval::PoseRelation parseRelation(const std::string& s) {
  if (s == "rot") return eval::PoseRelation::kRotation;
  if (s == "full") return eval::PoseRelation::kFull;
  if (s == "angle_deg") return eval::PoseRelation::kAngleDeg;
  return eval::PoseRelation::kTranslation;
}

std::optional<std::string> optionalPath(const std::string& s) {
  return s.empty() ? std::nullopt : std::optional<std::string>(s);
}

// Both were checked when the command line was read (addSeconds); converted here through the same checks.
eval::AssociationOptions associationOptions(const CommonOptions& o) {
  return {io::checkedSeconds(o.t_max_diff, atLeast(0, "s"), io::ValueSource::option("--t-max-diff")),
          io::checkedSeconds(o.t_offset, io::Range{}, io::ValueSource::option("--t-offset"))};
}

void loadBoth(const CommonOptions& o, Trajectory& ref, Trajectory& est) {
  const io::TrajectoryFormat format = io::parseTrajectoryFormat(o.format);
  // Output files are checked before the work so a typo does not cost a long evaluation.
  io::checkOutputFile(o.json, "--json");
  io::checkOutputFile(o.plot, "--plot");
  ref = io::readTrajectory(o.ref, format, optionalPath(o.ref_times));
  est = io::readTrajectory(o.est, format, optionalPath(o.est_times));
  if (ref.empty()) throw std::invalid_argument(o.ref + ": no poses");
  if (est.empty()) throw std::invalid_argument(o.est + ": no poses");
  spdlog::info("loaded {} reference poses from {}, {} estimated poses from {}", ref.size(), o.ref, est.size(), o.est);
}

// Runs a metric; its complaints (no matching stamps, a degenerate alignment...) name the files, as
// "EST (against REF): what".
template <typename Metric>
auto onFiles(const CommonOptions& o, Metric metric) {
  try {
    return metric();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{} (against {}): {}", o.est, o.ref, e.what()));
  }
}

Json commonJson(const char* metric, const CommonOptions& o, eval::PoseRelation relation, std::size_t pairs,
                std::size_t max_pairs, const eval::ErrorStatistics& s, eval::Alignment alignment,
                const eval::Sim3& transform) {
  Json j;
  j["metric"] = metric;
  j["reference"] = o.ref;
  j["estimate"] = o.est;
  j["pose_relation"] = eval::relationName(relation);
  j["unit"] = eval::relationUnit(relation);
  const Json stats = statisticsJson(s);
  for (auto it = stats.begin(); it != stats.end(); ++it) j[it.key()] = it.value();
  j["pairs"] = pairs;
  j["max_pairs"] = max_pairs;
  j["t_max_diff_s"] = o.t_max_diff;
  j["t_offset_s"] = o.t_offset;
  j["alignment"] = eval::alignmentName(alignment);
  j["alignment_transform"] = alignmentJson(transform);
  return j;
}

// The table on stdout, as evo prints it; -q (only errors) silences it: --json then holds the result.
void printResult(const std::string& title, std::size_t pairs, std::size_t max_pairs, const eval::ErrorStatistics& s) {
  if (!spdlog::should_log(spdlog::level::info)) return;
  fmt::print("{}\n\nmatched pose pairs: {} of max. {}\nvalues: {}\n\n{}", title, pairs, max_pairs, s.count,
             statisticsTable(s));
}

void runApe(const CommonOptions& o) {
  Trajectory ref, est;
  loadBoth(o, ref, est);
  eval::ApeOptions options{parseRelation(o.relation), parseAlignment(o.align), associationOptions(o)};
  const eval::ApeResult r = onFiles(o, [&] { return eval::computeApe(ref, est, options); });
  printResult(apeTitle(r), r.pairs, r.max_pairs, r.stats);
  if (!o.json.empty()) {
    const Json j = commonJson("ape", o, r.relation, r.pairs, r.max_pairs, r.stats, r.alignment, r.alignment_transform);
    io::writeFileAtomically(o.json, j.dump(2) + "\n");
  }
  if (!o.plot.empty()) {
    std::vector<std::size_t> all(r.pairs);
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    writePlot(plotData(apeTitle(r), eval::relationUnit(r.relation), r.times, r.errors, r.est_aligned, all, ref,
                       r.association.first),
              o.plot);
  }
}

void runRpe(const RpeCliOptions& c) {
  const CommonOptions& o = c.common;
  const bool frames = !(c.delta_unit == "meters" || c.delta_unit == "m");
  constexpr double kMaxFrames = 1e9;
  if (frames && !(c.delta >= 1 && c.delta <= kMaxFrames && c.delta == std::floor(c.delta)))
    throw std::invalid_argument(fmt::format(
        "--delta: with --delta-unit frames, expected a whole number of frames in [1, {:.0f}], got {}", kMaxFrames,
        c.delta));
  Trajectory ref, est;
  loadBoth(o, ref, est);
  eval::RpeOptions options;
  options.relation = parseRelation(o.relation);
  options.alignment = parseAlignment(o.align);
  options.association = associationOptions(o);
  options.delta = c.delta;
  options.unit = frames ? eval::DeltaUnit::kFrames : eval::DeltaUnit::kMeters;
  options.pairs_from_reference = c.pairs_from_reference;
  const eval::RpeResult r = onFiles(o, [&] { return eval::computeRpe(ref, est, options); });
  printResult(rpeTitle(r, options), r.pairs, r.max_pairs, r.stats);
  if (!o.json.empty()) {
    Json j = commonJson("rpe", o, r.relation, r.pairs, r.max_pairs, r.stats, r.alignment, r.alignment_transform);
    j["delta"] = c.delta;
    j["delta_unit"] = options.unit == eval::DeltaUnit::kFrames ? "frames" : "meters";
    j["pairs_from"] = options.pairs_from_reference ? "reference" : "estimate";
    io::writeFileAtomically(o.json, j.dump(2) + "\n");
  }
  if (!o.plot.empty()) {
    std::vector<std::size_t> second;
    for (const auto& pair : r.id_pairs) second.push_back(pair.second);
    writePlot(plotData(rpeTitle(r, options), eval::relationUnit(r.relation), r.times, r.errors, r.est_aligned, second,
                       ref, r.association.first),
              o.plot);
  }
}

std::vector<Eigen::Isometry3d> posesOf(const Trajectory& t) {
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(t.size());
  for (const auto& p : t) poses.push_back(p.T_world_body);
  return poses;
}

void runKitti(const CommonOptions& o) {
  Trajectory ref, est;
  loadBoth(o, ref, est);
  if (ref.size() != est.size())
    throw std::invalid_argument(fmt::format("KITTI drift matches poses by index: {} has {} poses but {} has {}", o.ref,
                                            ref.size(), o.est, est.size()));
  const eval::KittiDriftResult r = onFiles(o, [&] { return eval::computeKittiDrift(posesOf(ref), posesOf(est)); });
  if (spdlog::should_log(spdlog::level::info)) fmt::print("{}", kittiTable(r));
  if (!o.json.empty()) {
    Json j = kittiJson(r);
    j["reference"] = o.ref;
    j["estimate"] = o.est;
    io::writeFileAtomically(o.json, j.dump(2) + "\n");
  }
}

void addInputs(CLI::App* cmd, CommonOptions& o, const char* default_format) {
  o.format = default_format;
  cmd->add_option("ref", o.ref, "Reference (ground-truth) trajectory file")->required();
  cmd->add_option("est", o.est, "Estimated trajectory file")->required();
  cmd->add_option("--format", o.format, "Trajectory file format")->capture_default_str()
      ->check(CLI::IsMember({"tum", "kitti", "euroc"}));
  cmd->add_option("--ref-times", o.ref_times, "KITTI times.txt of the reference (seconds, one a line)");
  cmd->add_option("--est-times", o.est_times, "KITTI times.txt of the estimate");
  cmd->add_option("--json", o.json, "Write the figures as JSON to this file");
}

void addMetricOptions(CLI::App* cmd, CommonOptions& o) {
  cmd->add_option("--align", o.align, "Umeyama alignment of the estimate onto the reference")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "se3", "sim3"}));
  addSeconds(cmd, "--t-max-diff", o.t_max_diff, atLeast(0, "s"), "Largest time difference of an associated pair [s]")
      ->default_str("0.01");
  addSeconds(cmd, "--t-offset", o.t_offset, io::Range{}, "Time offset added to the estimate's stamps [s]")
      ->default_str("0");
  cmd->add_option("--pose-relation", o.relation, "Error measure")
      ->capture_default_str()
      ->check(CLI::IsMember({"trans", "rot", "full", "angle_deg"}));
  cmd->add_option("--plot", o.plot, "Write a PNG plot: error over time and the trajectory from above");
}

}  // namespace

void registerEval(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate a trajectory against ground truth (APE, RPE, KITTI drift)");
  eval->require_subcommand(1);

  auto ape = std::make_shared<CommonOptions>();
  auto* ape_cmd = eval->add_subcommand("ape", "Absolute pose error, as evo_ape");
  addInputs(ape_cmd, *ape, "tum");
  addMetricOptions(ape_cmd, *ape);
  ape_cmd->callback([ape] { runApe(*ape); });

  auto rpe = std::make_shared<RpeCliOptions>();
  auto* rpe_cmd = eval->add_subcommand("rpe", "Relative pose error with consecutive pairs, as evo_rpe");
  addInputs(rpe_cmd, rpe->common, "tum");
  addMetricOptions(rpe_cmd, rpe->common);
  addNumber(rpe_cmd, "--delta", rpe->delta, positive(""), "Distance between the poses of a pair (frames: an integer)")
      ->default_str("1");
  rpe_cmd->add_option("--delta-unit", rpe->delta_unit, "Unit of --delta")->capture_default_str()
      ->check(CLI::IsMember({"frames", "meters", "f", "m"}));
  rpe_cmd->add_flag("--pairs-from-reference", rpe->pairs_from_reference,
                    "With --delta-unit meters, measure the path on the reference (evo default: the estimate)");
  rpe_cmd->callback([rpe] { runRpe(*rpe); });

  auto kitti = std::make_shared<CommonOptions>();
  auto* kitti_cmd = eval->add_subcommand("kitti", "KITTI odometry devkit drift: t_err % and r_err deg/100 m");
  addInputs(kitti_cmd, *kitti, "kitti");
  kitti_cmd->callback([kitti] { runKitti(*kitti); });
}

}  // namespace drover::cli
