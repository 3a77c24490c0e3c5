#pragma once
// Each subcommand lives in its own cmd_<name>.cpp and registers itself on the root app.
// A command's callback throws on error; main() turns any exception into one line and exit code 2.
#include <CLI/CLI.hpp>

namespace drover::cli {

// Thrown by a command that did its work but must exit with another code than 0 (an interrupted `drover run`:
// 128 + the signal, as a shell reports it); main() prints nothing more.
struct ExitCode {
  int code;
};

void registerEval(CLI::App& app);
void registerInfo(CLI::App& app);
void registerSim(CLI::App& app);
void registerRun(CLI::App& app);
void registerLoop(CLI::App& app);      // cmd_loop.cpp: drover loop pair|eval
void registerGraph(CLI::App& app);     // cmd_graph.cpp: drover graph optimize
void registerFeatures(CLI::App& app);  // cmd_features.cpp: drover features detect|track
void registerConfig(CLI::App& app);    // cmd_config.cpp: drover config import-lvi-sam
// The two halves of `drover features`, each in its own file.
void registerFeaturesDetect(CLI::App& features);  // cmd_features_detect.cpp
void registerFeaturesTrack(CLI::App& features);   // cmd_features_track.cpp
void registerLoopEval(CLI::App& loop);            // cmd_loop_eval.cpp

}  // namespace drover::cli
