#pragma once
// Where and how `drover run` ends: its run folder is checked before any work, written as OUT.partial/ and swapped
// in as OUT when complete (io/output_paths.hpp), so a run killed while writing never leaves a folder that looks
// finished nor mixes new files with an earlier run's; SIGINT/SIGTERM stop the reading and the run writes what it
// processed.
#include <csignal>
#include <filesystem>
#include <string>

#include "io/output_paths.hpp"

namespace drover::cli {

// "" when DIR (an existing folder) may be replaced by a new run: it is empty, or an earlier run folder (a report.json
// of drover run and nothing but the files drover run writes); else why not.
std::string runFolderProblem(const std::filesystem::path& dir);

// --out's rules: an existing folder is replaced only when runFolderProblem says so.
io::StagingRules runFolderRules();

// While alive, the first SIGINT or SIGTERM only asks the run to stop (it then writes the outputs of the sweeps it
// processed); the handlers are reset by then, so a second signal kills at once. Restores the old handlers.
class StopOnSignal {
 public:
  StopOnSignal();
  ~StopOnSignal();
  StopOnSignal(const StopOnSignal&) = delete;
  StopOnSignal& operator=(const StopOnSignal&) = delete;
  int signal() const;  // the signal received, 0 while none
  bool requested() const { return signal() != 0; }

 private:
  struct sigaction old_int_ = {};
  struct sigaction old_term_ = {};
};

// "SIGINT", "SIGTERM" (else "signal N").
std::string signalName(int signal);

}  // namespace drover::cli
