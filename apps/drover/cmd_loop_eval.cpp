// drover loop eval: precision and recall of Scan Context place recognition (descriptor, ring-key database, shift
// search; no ICP). Mode A: along a dataset with ground truth (keyframes by ground-truth travel); mode B (--pairs):
// on labelled KITTI scan pairs. The data side is in loop_eval_course.cpp / loop_eval_pairs.cpp, the counting in
// loop/place_recognition_eval.hpp.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "apps/drover/eval_report.hpp"
#include "apps/drover/loop_eval.hpp"
#include "io/output_paths.hpp"
#include "io/trajectory_io.hpp"

namespace drover::cli {
namespace {

Json countsJson(const loop::PrCounts& c) {
  return Json{{"threshold", c.threshold}, {"precision", c.precision}, {"recall", c.recall}, {"f1", c.f1},
              {"tp", c.tp},               {"fp", c.fp},               {"fn", c.fn},         {"tn", c.tn}};
}

Json resultJson(const LoopEvalOptions& o, const LoopEvalData& d, const loop::PrCounts& c,
                const std::vector<loop::PrCounts>& curve) {
  Json j;
  j["dataset"] = o.dataset;
  j["mode"] = o.pairs.empty() ? "course" : "pairs";
  j["augmented"] = !o.no_augment;
  j["precision"] = c.precision;
  j["recall"] = c.recall;
  j["f1"] = c.f1;
  j["threshold"] = c.threshold;
  j["queries"] = c.queries;
  j["true_revisits"] = c.true_revisits;
  j["tp"] = c.tp;
  j["fp"] = c.fp;
  j["fn"] = c.fn;
  j["tn"] = c.tn;
  j["curve"] = Json::array();
  for (const loop::PrCounts& p : curve) j["curve"].push_back(countsJson(p));
  if (o.pairs.empty()) {
    j["keyframe_distance_m"] = o.keyframe_distance;
    j["true_distance_m"] = o.true_distance;
    j["correct_distance_m"] = 2 * o.true_distance;
    j["scans"] = d.scans;
    j["keyframes"] = d.keyframes;
    j["skipped_keyframes"] = d.skipped;
    j["narrowed_checked"] = d.narrowed_checked;
    j["narrowed_equals_full"] =
        d.narrowed_checked > 0 ? Json(static_cast<double>(d.narrowed_equal) / static_cast<double>(d.narrowed_checked))
                               : Json(nullptr);
  }
  j["false_positives"] = Json::array();
  for (const LoopEvalData::Detection& f : d.false_positives)
    j["false_positives"].push_back(Json{{"t_query", toSeconds(f.t_query)},
                                        {"t_candidate", toSeconds(f.t_candidate)},
                                        {"distance", f.distance},
                                        {"true_distance_m", f.true_distance}});
  j["descriptor_ms"] = d.descriptor_ms;
  j["query_ms"] = d.query_ms;
  return j;
}

void runLoopEval(const LoopEvalOptions& o) {
  if (o.quiet) spdlog::set_level(spdlog::level::err);
  io::checkOutputFile(o.json, "--json");  // before the evaluation, which reads a whole dataset
  const pipeline::OdometryConfig config = loopEvalConfig(o);
  const LoopEvalData d = o.pairs.empty() ? evaluateCourse(o, config) : evaluatePairs(o, config);
  const double threshold = config.loop.database.descriptor.threshold;
  const loop::PrCounts c = loop::countAt(d.queries, threshold);
  const std::vector<loop::PrCounts> curve =
      loop::precisionRecallCurve(d.queries, loop::thresholdRange(0.05, 0.5, 0.025));
  if (o.pairs.empty())
    spdlog::info("{} scans, {} keyframes ({} skipped), {} queries, {} with a true revisit (within {:.1f} m; right "
                 "place within {:.1f} m)",
                 d.scans, d.keyframes, d.skipped, c.queries, c.true_revisits, o.true_distance, 2 * o.true_distance);
  else
    spdlog::info("{} pairs, {} same place", c.queries, c.true_revisits);
  spdlog::info("threshold {:.3f}: TP {} FP {} FN {} TN {}; precision {:.3f}, recall {:.3f}, F1 {:.3f}", threshold, c.tp,
               c.fp, c.fn, c.tn, c.precision, c.recall, c.f1);
  for (const loop::PrCounts& p : curve)
    spdlog::info("  threshold {:.3f}: precision {:.3f} recall {:.3f}", p.threshold, p.precision, p.recall);
  if (d.narrowed_checked > 0)
    spdlog::info("prior-narrowed shift (ground-truth yaw prior) equals the full search's on {}/{} detected right "
                 "places",
                 d.narrowed_equal, d.narrowed_checked);
  spdlog::info("descriptor {:.2f} ms, query {:.3f} ms (means)", d.descriptor_ms, d.query_ms);
  if (!o.json.empty()) io::writeFileAtomically(o.json, resultJson(o, d, c, curve).dump(2) + "\n");
}

}  // namespace

void registerLoopEval(CLI::App& loop) {
  auto* cmd = loop.add_subcommand("eval", "Precision and recall of Scan Context place recognition (no ICP) along a "
                                          "dataset with ground truth, or on labelled KITTI scan pairs (--pairs)");
  auto o = std::make_shared<LoopEvalOptions>();
  cmd->add_option("dataset", o->dataset, "Dataset folder (--pairs: a KITTI sequence folder with velodyne/)")
      ->required();
  cmd->add_option("--format", o->format, "Dataset format")
      ->check(CLI::IsMember({"sim", "kitti", "kitti-raw", "bag"}))
      ->capture_default_str();
  cmd->add_option("--config", o->config, "Platform config (layout, features, loop sections); default: KITTI HDL-64E");
  addNumber(cmd, "--keyframe-distance", o->keyframe_distance, positive("m"),
            "[m] ground-truth travel between keyframes (> 0)")
      ->default_str("1");
  addNumber(cmd, "--true-distance", o->true_distance, positive("m"),
            "[m] a query has a true revisit when an eligible keyframe is this close; the best candidate is the "
            "right place within twice this (> 0)")
      ->default_str("3");
  addNumber(cmd, "--threshold", o->threshold, between(0, 2, ""),
            "Scan Context distance threshold in [0, 2] (default: the config's)");
  cmd->add_flag("--no-augment", o->no_augment, "No lateral augmentation of the queries");
  cmd->add_option("--pairs", o->pairs, "Pair list 'i j label' per line (mode B)");
  cmd->add_option("--json", o->json, "Write precision, recall, f1, counts, curve and timings as JSON");
  addInteger(cmd, "--max-frames", o->max_frames, 1, 1'000'000'000, "Read at most N >= 1 scans (default: all)");
  cmd->add_flag("-q,--quiet", o->quiet, "Only print errors");
  cmd->callback([o] { runLoopEval(*o); });
}

}  // namespace drover::cli
