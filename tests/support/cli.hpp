#pragma once
// Runs the drover binary for CLI tests: exit code and combined output.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace drover::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line (stderr already redirected by the caller): its exit code (-1 when a signal ended the
// shell) and everything it printed.
inline CliResult runShell(const std::string& command) {
  CliResult r;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CliResult runDrover(const std::string& args) {
  return runShell(std::string(DROVER_BINARY) + " " + args + " 2>&1");
}

// A JSON file the command wrote (a failed expectation when it cannot be opened).
inline nlohmann::json readJson(const std::filesystem::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in.good()) << p;
  return nlohmann::json::parse(in);
}

// A JSON-lines file (sweeps.jsonl) as an array, one element a line.
inline nlohmann::json readJsonLines(const std::filesystem::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in.good()) << p;
  nlohmann::json all = nlohmann::json::array();
  for (std::string line; std::getline(in, line);) all.push_back(nlohmann::json::parse(line));
  return all;
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A platform file of the repository's config/ folder.
inline std::string config(const std::string& name) { return std::string(DROVER_SOURCE_DIR) + "/config/" + name; }

// The lines of a text, without their line breaks.
inline std::vector<std::string> linesOf(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

}  // namespace drover::test
