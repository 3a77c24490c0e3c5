#include "apps/drover/run_folder.hpp"

#include <atomic>
#include <fstream>
#include <nlohmann/json.hpp>

namespace drover::cli {
namespace {
namespace fs = std::filesystem;

// Every file drover run writes into its folder (run_output.hpp; keep in step with it), and the report that
// tools/course_report.py adds to it (scripts/run.sh), which describes the run it replaces.
constexpr const char* kRunFiles[] = {"trajectory.tum",  "trajectory_kitti.txt", "keyframes.tum",
                                     "trajectory_imu_rate.tum", "trajectory_vis.tum", "map.pcd",
                                     "map.ply", "report.json", "sweeps.jsonl", "vis_frames.jsonl", "ape.json",
                                     "ape.png", "course_report.json"};

bool isRunFile(const std::string& name) {
  for (const char* f : kRunFiles)
    if (name == f) return true;
  return io::isStagingLeftover(name);
}

// A report.json that drover run wrote: a JSON object with its counts and its sweeps' (or the VIS's) summary; "scans"
// is how earlier versions listed the sweeps.
bool isRunReport(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("counts") &&
         (j.contains("sweeps_logged") || j.contains("scans") || j.contains("vis"));
}

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "read in a signal handler");

extern "C" void onStopSignal(int signal) {
  int none = 0;
  const bool first = g_signal.compare_exchange_strong(none, signal);
  struct sigaction fallback {};
  fallback.sa_handler = SIG_DFL;
  sigemptyset(&fallback.sa_mask);
  sigaction(SIGINT, &fallback, nullptr);  // the second signal, either one, kills
  sigaction(SIGTERM, &fallback, nullptr);
  // The sa_mask below holds the other signal back only in the thread running this handler: with the run's threads
  // the second can arrive in another thread while the first is here (seen: 2 runs in 6 under load exited 143 after
  // a SIGTERM and a SIGINT). That one is the second: pending on this thread, it kills once the handler returns.
  if (!first) raise(signal);
}

}  // namespace

std::string runFolderProblem(const fs::path& dir) {
  std::error_code ec;
  bool has_report = false, empty = true;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    empty = false;
    const std::string name = e.path().filename().string();
    if (!isRunFile(name)) return "holds " + name + ", which drover run does not write";
    has_report = has_report || name == "report.json";
  }
  if (ec) return "cannot be listed: " + ec.message();
  if (empty) return "";
  if (!has_report) return "is not an earlier run folder (no report.json)";
  if (!isRunReport(dir / "report.json")) return "holds a report.json that drover run did not write";
  return "";
}

io::StagingRules runFolderRules() {
  io::StagingRules rules;
  rules.replaceable = runFolderProblem;
  rules.refusal = "drover run replaces only an earlier run folder";
  return rules;
}

StopOnSignal::StopOnSignal() {
  g_signal.store(0);
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);  // the other signal waits for the handler, then finds the default action: kills
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &old_int_);
  sigaction(SIGTERM, &action, &old_term_);
}

StopOnSignal::~StopOnSignal() {
  sigaction(SIGINT, &old_int_, nullptr);
  sigaction(SIGTERM, &old_term_, nullptr);
}

int StopOnSignal::signal() const { return g_signal.load(); }

std::string signalName(int signal) {
  if (signal == SIGINT) return "SIGINT";
  if (signal == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signal);
}

}  // namespace drover::cli
