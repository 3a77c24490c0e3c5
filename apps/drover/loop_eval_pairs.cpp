// drover loop eval, mode B: labelled pairs of KITTI scans (the SSC / Scan Context pair lists: "i j label" per line,
// label 1 = same place), each scored by the Scan Context distance of scan i (database side) and scan j (the query,
// laterally augmented unless --no-augment), full shift search.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "apps/drover/loop_eval.hpp"
#include "io/kitti_common.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "loop/scan_context.hpp"
#include "pipeline/scan_pair.hpp"

namespace drover::cli {
namespace {

namespace fs = std::filesystem;

struct Pair {
  int i = 0, j = 0;
  bool same = false;
  std::size_t line = 0;
};

std::vector<Pair> readPairs(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument("pairs file " + path + " not found or unreadable");
  std::vector<Pair> pairs;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream s(text);
    Pair p;
    int label = -1;
    std::string rest;
    if (!(s >> p.i >> p.j >> label) || (s >> rest) || p.i < 0 || p.j < 0 || (label != 0 && label != 1))
      throw std::invalid_argument(
          fmt::format("pairs file {} line {}: expected 'i j label' (frame indices >= 0, label 0 or 1), got '{}'",
                      path, line, text));
    p.same = label == 1;
    p.line = line;
    pairs.push_back(p);
  }
  if (pairs.empty()) throw std::invalid_argument("pairs file " + path + " lists no pair");
  return pairs;
}

std::string scanPath(const std::string& sequence, int frame) {
  return (fs::path(sequence) / "velodyne" / fmt::format("{:06d}.bin", frame)).string();
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

pipeline::OdometryConfig loopEvalConfig(const LoopEvalOptions& o) {
  pipeline::OdometryConfig c =
      o.config.empty() ? pipeline::OdometryConfig::kittiHdl64() : io::loadOdometryConfig(o.config);
  loop::ScanContextConfig& sc = c.loop.database.descriptor;
  if (o.threshold >= 0) sc.threshold = o.threshold;
  if (o.no_augment) sc.lateral_steps = 0;
  if (std::string e = sc.validate(); !e.empty()) throw std::invalid_argument("scan context: " + e);
  return c;
}

lidar::PointCloud descriptorCloud(LidarScan scan, const pipeline::OdometryConfig& config,
                                  const std::string& name) {
  return pipeline::prepareScan(scan, config, name).full;
}

LoopEvalData evaluatePairs(const LoopEvalOptions& o, const pipeline::OdometryConfig& config) {
  if (!fs::is_directory(o.dataset)) throw std::invalid_argument("dataset " + o.dataset + " not found");
  const std::vector<Pair> pairs = readPairs(o.pairs);
  for (const Pair& p : pairs)  // every scan first, so that a bad list fails at once
    for (int frame : {p.i, p.j})
      if (!fs::exists(scanPath(o.dataset, frame)))
        throw std::invalid_argument(fmt::format("pairs file {} line {}: scan {} not found", o.pairs, p.line,
                                                scanPath(o.dataset, frame)));
  const loop::ScanContextConfig& sc = config.loop.database.descriptor;
  std::map<int, loop::AugmentedScanContext> cache;  // by frame; bounded below
  LoopEvalData d;
  auto describe = [&](int frame) -> const loop::AugmentedScanContext& {
    if (auto it = cache.find(frame); it != cache.end()) return it->second;
    if (cache.size() > 2000) cache.clear();  // ~90 kB each with augmentation
    const std::string path = scanPath(o.dataset, frame);
    LidarScan scan = io::readKittiBin(path, 0, 0);
    const auto t0 = std::chrono::steady_clock::now();
    loop::AugmentedScanContext a = loop::makeAugmentedScanContext(descriptorCloud(std::move(scan), config, path), sc);
    d.descriptor_ms += msSince(t0);
    ++d.keyframes;
    return cache.emplace(frame, std::move(a)).first->second;
  };
  for (const Pair& p : pairs) {
    const loop::ScanContext a = describe(p.i).descriptors[0];
    const loop::AugmentedMatch m = loop::augmentedShiftSearch(a, describe(p.j), std::nullopt, sc);
    d.queries.push_back({true, m.match.distance, p.same, p.same});
  }
  d.scans = d.keyframes;
  if (d.keyframes > 0) d.descriptor_ms /= static_cast<double>(d.keyframes);
  return d;
}

}  // namespace drover::cli
