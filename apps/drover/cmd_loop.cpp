// drover loop: loop-closure tools. `pair` compares two scans (Scan Context distance, shift, yaw, and the
// verifying scan match); `eval` measures place recognition on a simulated course against its ground truth
// (cmd_loop_eval.cpp). The work is in src/loop and src/pipeline.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>

#include "apps/drover/commands.hpp"
#include "apps/drover/eval_report.hpp"
#include "io/kitti_common.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/output_paths.hpp"
#include "io/trajectory_io.hpp"
#include "pipeline/scan_pair.hpp"

namespace drover::cli {
namespace {

constexpr double kDeg = 180.0 / std::numbers::pi;

struct PairOptions {
  std::string a, b, config, json;
  bool quiet = false;
};

// Without a config: the KITTI HDL-64E as config/kitti.yaml describes it (the .bin files are KITTI's format).
pipeline::OdometryConfig pairConfig(const PairOptions& o) {
  if (!o.config.empty()) return io::loadOdometryConfig(o.config);
  return pipeline::OdometryConfig::kittiHdl64();
}

Json verificationJson(const loop::LoopVerification& v) {
  const Eigen::Isometry3d& T = v.T_candidate_query;
  const Eigen::Quaterniond q(T.linear());
  return Json{{"accepted", v.accepted},
              {"reason", v.reason},
              {"status", v.match_status},
              {"converged", v.converged},
              {"iterations", v.iterations},
              {"fitness", v.fitness},
              {"inliers", v.inliers},
              {"inlier_ratio", v.inlier_ratio},
              {"t_A_B", {T.translation().x(), T.translation().y(), T.translation().z()}},
              {"q_A_B_xyzw", {q.x(), q.y(), q.z(), q.w()}},
              {"yaw_deg", std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * kDeg},
              {"correction_translation", v.correction_translation},
              {"correction_rotation_deg", v.correction_rotation * kDeg}};
}

void runPair(const PairOptions& o) {
  if (o.quiet) spdlog::set_level(spdlog::level::err);
  io::checkOutputFile(o.json, "--json");
  for (const std::string& p : {o.a, o.b})
    if (!std::filesystem::exists(p)) throw std::invalid_argument("scan " + p + " not found");
  const pipeline::OdometryConfig config = pairConfig(o);
  const pipeline::ScanPairResult r =
      pipeline::compareScans(io::readKittiBin(o.a, 0, 0), io::readKittiBin(o.b, 0, 0), config, o.a, o.b);
  const double threshold = config.loop.database.descriptor.threshold;
  const Eigen::Isometry3d& T = r.icp.T_candidate_query;
  spdlog::info("A: {} ({} points), B: {} ({} points)", o.a, r.points_a, o.b, r.points_b);
  spdlog::info(
      "scan context: distance {:.4f} ({} threshold {:.2f}), shift {}, yaw {:.1f} deg; plain (no lateral "
      "augmentation) {:.4f}",
      r.match.match.distance, r.same_place ? "same place, under the" : "different places, over the", threshold,
      r.match.match.shift, r.match.match.yaw * kDeg, r.plain.distance);
  spdlog::info("icp: {}; T_A_B translation ({:.3f}, {:.3f}, {:.3f}) m, yaw {:.2f} deg", r.icp.reason,
               T.translation().x(), T.translation().y(), T.translation().z(),
               std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * kDeg);
  if (o.json.empty()) return;
  Json j;
  j["a"] = o.a;
  j["b"] = o.b;
  j["distance"] = r.match.match.distance;
  j["shift"] = r.match.match.shift;
  j["yaw_deg"] = r.match.match.yaw * kDeg;
  j["same_place"] = r.same_place;
  j["threshold"] = threshold;
  j["plain_distance"] = r.plain.distance;
  j["virtual_offset"] = {r.match.offset.x(), r.match.offset.y()};
  j["icp"] = verificationJson(r.icp);
  io::writeFileAtomically(o.json, j.dump(2) + "\n");
}

void registerPair(CLI::App& loop) {
  auto* cmd = loop.add_subcommand("pair",
                                  "Scan Context distance, shift and yaw of two KITTI .bin scans, and the "
                                  "scan match of B onto A that would verify the loop");
  auto o = std::make_shared<PairOptions>();
  cmd->add_option("a", o->a, "Scan A (.bin: float32 x, y, z, reflectance), the earlier visit")->required();
  cmd->add_option("b", o->b, "Scan B (.bin), the query")->required();
  cmd->add_option("--config", o->config, "Platform config (layout, features, loop sections); default: KITTI HDL-64E");
  cmd->add_option("--json", o->json, "Write distance, shift, yaw_deg, same_place and icp as JSON");
  cmd->add_flag("-q,--quiet", o->quiet, "Only print errors");
  cmd->callback([o] { runPair(*o); });
}

}  // namespace

void registerLoop(CLI::App& app) {
  auto* cmd = app.add_subcommand("loop", "Loop closure: compare two scans, evaluate place recognition on a course");
  cmd->require_subcommand(1);
  registerPair(*cmd);
  registerLoopEval(*cmd);
}

}  // namespace drover::cli
