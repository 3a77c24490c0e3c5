// drover config import-lvi-sam: LIO-SAM / LVI-SAM parameter files -> a Drover platform config on stdout. The
// mapping is io/lvi_sam_import.hpp; this file checks the result with the loaders `drover run --config` uses (so
// what it prints is a config drover run accepts) and lists the parameters it did not import on stderr.
#include <fmt/format.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "apps/drover/commands.hpp"
#include "io/config.hpp"
#include "io/error.hpp"
#include "io/lvi_sam_import.hpp"
#include "io/odometry/odometry_config_io.hpp"
#include "io/visual/vio_config_io.hpp"
#include "io/visual/visual_config_io.hpp"

namespace drover::cli {
namespace {
namespace fs = std::filesystem;

struct ImportOptions {
  std::vector<std::string> files;
};

// stdout carries the config, so messages (and main()'s error line) go to stderr from here on.
void logToStderr() {
  const auto level = spdlog::default_logger()->level();
  auto logger = spdlog::stderr_color_mt("drover-config");
  logger->set_level(level);
  spdlog::set_default_logger(logger);
  spdlog::set_pattern("%^[%l]%$ %v");
}

// Loads the generated text with every config reader drover run uses; a value they reject is an error naming the
// input files, the generated key and what is wrong (the importer's own checks should make this unreachable).
void checkAcceptedByRun(const std::string& yaml, const std::vector<std::string>& inputs) {
  const fs::path tmp = fs::temp_directory_path() / fmt::format("drover-import-lvi-sam-{}.yaml", ::getpid());
  std::ofstream(tmp, std::ios::binary) << yaml;
  std::string error;
  try {
    io::loadDatasetOptions(tmp.string());
    io::loadOdometryConfig(tmp.string());
    io::loadVisualConfig(tmp.string());
    io::loadVioConfig(tmp.string());
  } catch (const io::IoError& e) {
    error = std::string(e.what()).substr(e.file().size());  // "(line N, key 'a.b'): what"
  }
  std::error_code ec;
  fs::remove(tmp, ec);
  if (error.empty()) return;
  std::string names;
  for (const std::string& f : inputs) names += (names.empty() ? "" : ", ") + f;
  throw io::IoError(names, "", "the imported values do not form a config drover run accepts: generated config " +
                                   error);
}

void runImport(const ImportOptions& o) {
  logToStderr();
  const io::LviSamImport r = io::importLviSamFiles(o.files);
  checkAcceptedByRun(r.yaml, o.files);
  fmt::print("{}", r.yaml);
  std::fflush(stdout);
  spdlog::info("imported {} parameters; {} not imported:", r.mapped.size(), r.ignored.size());
  for (const io::LviSamKey& k : r.ignored) spdlog::info("  {}: {} -- {}", k.file, k.key, k.note);
}

}  // namespace

void registerConfig(CLI::App& app) {
  auto* config = app.add_subcommand("config", "Platform config tools");
  config->require_subcommand(1);
  auto* cmd = config->add_subcommand(
      "import-lvi-sam", "Convert LIO-SAM / LVI-SAM parameter files (params_lidar.yaml, params_camera.yaml, "
                        "params.yaml) into a platform config on stdout; what is not imported goes to stderr");
  auto o = std::make_shared<ImportOptions>();
  cmd->add_option("files", o->files, "LIO-SAM params.yaml or LVI-SAM params_lidar.yaml, and/or params_camera.yaml")
      ->required();
  cmd->callback([o] { runImport(*o); });
}

}  // namespace drover::cli
