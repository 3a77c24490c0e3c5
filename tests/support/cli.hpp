#pragma once
// Runs the drover binary for CLI tests: exit code and combined output.
#include <array>
#include <cstdio>
#include <string>
#include <sys/wait.h>

namespace drover::test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

inline CliResult runDrover(const std::string& args) {
  CliResult r;
  const std::string cmd = std::string(DROVER_BINARY) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace drover::test
