// drover graph optimize: a g2o 3-D pose graph (VERTEX_SE3:QUAT / EDGE_SE3:QUAT / FIX) optimised by the backend's
// PoseGraph (Ceres Levenberg-Marquardt, sparse Cholesky) and written back with the optimised vertices. The maths
// is in src/backend/pose_graph, the file format in src/io/g2o_io, the conversion in src/io/odometry.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "backend/pose_graph.hpp"
#include "io/g2o_io.hpp"
#include "io/output_paths.hpp"
#include "io/odometry/g2o_pose_graph.hpp"
#include "io/trajectory_io.hpp"

namespace drover::cli {
namespace {

struct GraphOptimizeOptions {
  std::string in, out, json;
  int max_iterations = 100;
  // A g2o file is a benchmark graph whose edges are all trusted measurements: no robust loss unless asked.
  std::string loss = "none";
  double loss_scale = 3.0;  // [sigmas]
  int threads = 1;
};

nlohmann::ordered_json resultJson(const GraphOptimizeOptions& o, const backend::PoseGraphResult& r) {
  nlohmann::ordered_json j;
  j["input"] = o.in;
  j["output"] = o.out;
  j["nodes"] = r.nodes;
  j["edges"] = r.edges;
  j["initial_cost"] = r.initial_cost;
  j["final_cost"] = r.final_cost;
  j["iterations"] = r.iterations;
  j["time_ms"] = r.time_ms;
  j["converged"] = r.converged;
  j["reason"] = r.reason;
  j["loss"] = o.loss;
  j["loss_scale"] = o.loss_scale;
  j["linear_solver"] = r.linear_solver;
  return j;
}

void runOptimize(const GraphOptimizeOptions& o) {
  backend::PoseGraphConfig config;
  config.max_iterations = o.max_iterations;
  config.loop_loss = backend::parseRobustLoss(o.loss);
  config.loop_loss_scale = o.loss_scale;
  config.threads = o.threads;
  const std::string why = config.validate();
  if (!why.empty()) throw std::invalid_argument("graph optimize: " + why);
  io::checkOutputFile(o.out, "output");
  io::checkOutputFile(o.json, "--json");

  io::G2oGraph g2o = io::readG2o(o.in);
  backend::PoseGraph graph = io::toPoseGraph(g2o, config, o.in);
  spdlog::info("{}: {} nodes, {} edges ({} fixed)", o.in, graph.size(), graph.edgeCount(),
               g2o.fixed.empty() ? std::size_t{1} : g2o.fixed.size());
  const backend::PoseGraphResult r = graph.optimize();
  if (!r.usable) throw std::runtime_error(fmt::format("{}: the solver failed: {}", o.in, r.reason));
  io::updateVertexPoses(g2o, graph);
  io::writeG2o(o.out, g2o);
  // Ceres costs, 0.5 sum rho(|r|^2) -- half of g2o's chi2 (io/odometry/g2o_pose_graph.hpp).
  spdlog::info("initial cost {:.6g}, final cost {:.9g}, {} iterations, {:.1f} ms ({}; {})", r.initial_cost,
               r.final_cost, r.iterations, r.time_ms, r.linear_solver, r.reason);
  if (!r.converged) spdlog::warn("not converged within {} iterations", o.max_iterations);
  spdlog::info("wrote {}", o.out);
  if (!o.json.empty()) io::writeFileAtomically(o.json, resultJson(o, r).dump(2) + "\n");
}

}  // namespace

void registerGraph(CLI::App& app) {
  auto* graph = app.add_subcommand("graph", "Pose-graph tools: optimize a g2o 3-D pose graph");
  graph->require_subcommand(1);
  graph->fallthrough();  // -q after `graph optimize` reaches the root app
  auto* cmd = graph->add_subcommand("optimize", "Optimise a g2o pose graph (VERTEX_SE3:QUAT, EDGE_SE3:QUAT, FIX)");
  auto o = std::make_shared<GraphOptimizeOptions>();
  cmd->add_option("input", o->in, "g2o file to read")->required();
  cmd->add_option("output", o->out, "g2o file to write, with the optimised vertices (atomically)")->required();
  addInteger(cmd, "--max-iterations", o->max_iterations, 1, 1'000'000, "Levenberg-Marquardt iterations (>= 1)")
      ->default_str("100");
  cmd->add_option("--loss", o->loss, "Robust loss on loop edges (ids not consecutive)")
      ->check(CLI::IsMember({"none", "huber", "cauchy"}))
      ->capture_default_str();
  addNumber(cmd, "--loss-scale", o->loss_scale, positive("sigmas"), "Loss scale in whitened units (sigmas, > 0)")
      ->default_str("3");
  addInteger(cmd, "--threads", o->threads, 1, 1024, "Ceres threads (1..1024)")->default_str("1");
  cmd->add_option("--json", o->json, "Also write the figures as JSON to this file");
  cmd->callback([o] { runOptimize(*o); });
}

}  // namespace drover::cli
