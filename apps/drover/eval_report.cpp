#include "apps/drover/eval_report.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "io/trajectory_io.hpp"

extern char** environ;

namespace drover::cli {

namespace {

const char* alignmentLine(eval::Alignment a) {
  switch (a) {
    case eval::Alignment::kNone: return "(not aligned)";
    case eval::Alignment::kSe3: return "(with SE(3) Umeyama alignment)";
    case eval::Alignment::kSim3: return "(with Sim(3) Umeyama alignment)";
  }
  return "";
}

}  // namespace

std::string apeTitle(const eval::ApeResult& r) {
  return fmt::format("APE w.r.t. {} ({})\n{}", eval::relationTitle(r.relation), eval::relationUnit(r.relation),
                     alignmentLine(r.alignment));
}

std::string rpeTitle(const eval::RpeResult& r, const eval::RpeOptions& o) {
  const bool frames = o.unit == eval::DeltaUnit::kFrames;
  return fmt::format("RPE w.r.t. {} ({})\nfor delta = {} ({}) using consecutive pairs{}\n{}",
                     eval::relationTitle(r.relation), eval::relationUnit(r.relation), o.delta, frames ? "frames" : "m",
                     !frames && o.pairs_from_reference ? " (path of the reference)" : "", alignmentLine(r.alignment));
}

std::string statisticsTable(const eval::ErrorStatistics& s) {
  std::string out;
  const std::pair<const char*, double> rows[] = {{"max", s.max},   {"mean", s.mean}, {"median", s.median},
                                                 {"min", s.min},   {"rmse", s.rmse}, {"sse", s.sse},
                                                 {"std", s.std}};
  for (const auto& [name, value] : rows) out += fmt::format("{:>10}\t{:.6f}\n", name, value);
  return out;
}

std::string kittiTable(const eval::KittiDriftResult& r) {
  std::string out = fmt::format("KITTI odometry drift ({} segments, ground-truth path {:.3f} m)\n\n", r.segments.size(),
                                r.path_length);
  out += fmt::format("{:>10}{:>10}{:>12}{:>20}\n", "length[m]", "segments", "t_err[%]", "r_err[deg/100m]");
  for (const auto& l : r.per_length) {
    if (l.segments == 0) {
      out += fmt::format("{:>10.0f}{:>10}{:>12}{:>20}\n", l.length, 0, "-", "-");
      continue;
    }
    out += fmt::format("{:>10.0f}{:>10}{:>12.4f}{:>20.4f}\n", l.length, l.segments, l.t_err_percent,
                       l.r_err_deg_per_100m);
  }
  out += fmt::format("{:>10}{:>10}{:>12.4f}{:>20.4f}\n", "all", r.segments.size(), r.t_err_percent,
                     r.r_err_deg_per_100m);
  return out;
}

Json statisticsJson(const eval::ErrorStatistics& s) {
  Json j;
  j["max"] = s.max;
  j["min"] = s.min;
  j["std"] = s.std;
  j["median"] = s.median;
  j["mean"] = s.mean;
  j["rmse"] = s.rmse;
  j["sse"] = s.sse;
  j["count"] = s.count;
  return j;
}

Json alignmentJson(const eval::Sim3& a) {
  Json j;
  Json R = Json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push_back(a.R(r, c));
  j["rotation_row_major"] = R;
  j["translation"] = {a.t.x(), a.t.y(), a.t.z()};
  j["scale"] = a.scale;
  return j;
}

Json kittiJson(const eval::KittiDriftResult& r) {
  Json j;
  j["metric"] = "kitti";
  j["t_err_percent"] = r.t_err_percent;
  j["r_err_deg_per_100m"] = r.r_err_deg_per_100m;
  j["segments"] = r.segments.size();
  j["path_length_m"] = r.path_length;
  Json per = Json::array();
  for (const auto& l : r.per_length)
    per.push_back({{"length_m", l.length},
                   {"segments", l.segments},
                   {"t_err_percent", l.t_err_percent},
                   {"r_err_deg_per_100m", l.r_err_deg_per_100m}});
  j["per_length"] = per;
  return j;
}

namespace {

namespace fs = std::filesystem;

fs::path tempPath(const char* suffix) {
  static std::atomic<int> counter{0};
  return fs::temp_directory_path() / fmt::format("drover_plot_{}_{}{}", ::getpid(), counter++, suffix);
}

Json plotJson(const PlotData& d) {
  Json j;
  j["title"] = d.title;
  j["unit"] = d.unit;
  const Time t0 = d.times.empty() ? 0 : d.times.front();
  Json t = Json::array(), e = Json::array(), ex = Json::array(), ey = Json::array();
  for (std::size_t i = 0; i < d.errors.size(); ++i) {
    t.push_back(toSeconds(d.times[i] - t0));
    e.push_back(d.errors[i]);
    ex.push_back(d.est_at_errors[i].x());
    ey.push_back(d.est_at_errors[i].y());
  }
  Json rx = Json::array(), ry = Json::array();
  for (const auto& p : d.ref_path) {
    rx.push_back(p.x());
    ry.push_back(p.y());
  }
  j["seconds_from_start"] = t;
  j["error"] = e;
  j["est_x"] = ex;
  j["est_y"] = ey;
  j["ref_x"] = rx;
  j["ref_y"] = ry;
  return j;
}

std::string firstLine(const fs::path& p) {
  std::ifstream in(p);
  std::string line, last;
  // The last non-empty line of a Python traceback says what failed; our script prints a single line.
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last.empty() ? "no message" : last;
}

// Runs `python script data png` with stdout and stderr into `log`; returns the exit status, or -1 with `why`.
int runScript(const std::string& python, const std::string& script, const fs::path& data, const std::string& png,
              const fs::path& log, std::string& why) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, 2, 1);
  std::vector<std::string> args{python, script, data.string(), png};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, python.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    why = python + " could not be run (" + std::strerror(rc) + ")";
    return -1;
  }
  int status = 0;
  if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status)) {
    why = python + " did not finish normally";
    return -1;
  }
  return WEXITSTATUS(status);
}

}  // namespace

// Errors at the estimate poses est_aligned[k] for k in `at`; the reference path for context.
PlotData plotData(const std::string& title, const char* unit, const std::vector<Time>& times,
                  const std::vector<double>& errors, const Trajectory& est_aligned, const std::vector<std::size_t>& at,
                  const Trajectory& ref, const std::vector<std::size_t>& ref_index) {
  PlotData d;
  d.title = title;
  d.unit = unit;
  d.times = times;
  d.errors = errors;
  for (const std::size_t k : at) d.est_at_errors.push_back(est_aligned[k].T_world_body.translation());
  for (const std::size_t i : ref_index) d.ref_path.push_back(ref[i].T_world_body.translation());
  return d;
}

bool writePlot(const PlotData& data, const std::string& png) {
  // DROVER_PYTHON overrides the interpreter (tests use it to simulate a machine without python3).
  const char* env = std::getenv("DROVER_PYTHON");
  const std::string python = env && *env ? env : "/usr/bin/python3";
  const std::string script = std::string(DROVER_TOOLS_DIR) + "/plot_trajectory.py";
  const fs::path json = tempPath(".json");
  const fs::path log = tempPath(".log");
  std::string why;
  int status = -1;
  try {
    io::writeFileAtomically(json.string(), plotJson(data).dump());
    status = runScript(python, script, json, png, log, why);
    if (status > 0) why = firstLine(log);
  } catch (const std::exception& e) {
    why = e.what();
  }
  std::error_code ec;
  fs::remove(json, ec);
  fs::remove(log, ec);
  if (status == 0) {
    spdlog::info("plot written to {}", png);
    return true;
  }
  spdlog::warn("plot skipped: {}", why);
  return false;
}

}  // namespace drover::cli
