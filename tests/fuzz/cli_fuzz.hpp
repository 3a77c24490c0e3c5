#pragma once
// CLI contract fuzzing through the drover binary. A case is one table row: the arguments (with {placeholders} for
// the fixtures and a fresh {out} folder), whether the input is certainly bad, what the error line must name, and
// the outputs a success must leave. The contract checked for every row:
//   - exit 0 with every listed output present and non-empty, or
//   - exit 2 with exactly one `[error]` line, which names the offending input (file or option), and no listed
//     output that looks complete;
//   - never a signal, another exit code, or a run past the row's time limit (the command runs under `timeout` and
//     a 4 GiB address-space limit, so a runaway allocation is a failure, not a stalled suite).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli.hpp"

namespace drover::test::fuzz {
namespace fs = std::filesystem;

enum class Expect {
  kError,   // bad input: must exit 2
  kEither,  // mutated or borderline input: exit 0 with outputs, or exit 2
  kOk,      // good input: must exit 0
};

struct CliCase {
  std::string args;  // after `drover`; {placeholders} expanded
  Expect expect = Expect::kEither;
  std::string names = "";                 // the [error] line must contain this ({placeholders} expanded)
  std::vector<std::string> outputs = {};  // files a success writes ({placeholders} expanded)
  int timeout_s = 30;
};

// exit_code 124: timed out; >= 128 or -1: killed by a signal.
using CliRun = CliResult;

inline CliRun runCli(const std::string& args, int timeout_s) {
  return runShell("ulimit -v 4194304; exec timeout -k 2 " + std::to_string(timeout_s) + " " +
                  std::string(DROVER_BINARY) + " " + args + " 2>&1");
}

inline std::string expand(std::string s, const std::map<std::string, std::string>& vars) {
  for (const auto& [key, value] : vars)
    for (std::size_t p = s.find(key); p != std::string::npos; p = s.find(key, p + value.size()))
      s.replace(p, key.size(), value);
  return s;
}

inline std::vector<std::string> errorLinesOf(const std::string& output) {
  std::vector<std::string> lines;
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);)
    if (l.find("[error]") != std::string::npos) lines.push_back(l);
  return lines;
}

// "" when the run keeps the contract, else why not.
inline std::string contractBreach(const CliCase& c, const CliRun& r, const std::map<std::string, std::string>& vars) {
  const auto errors = errorLinesOf(r.output);
  if (r.exit_code == 124) return "ran past " + std::to_string(c.timeout_s) + " s";
  if (r.exit_code == 0) {
    if (c.expect == Expect::kError) return "exit 0 on bad input";
    for (const std::string& o : c.outputs) {
      const fs::path p = expand(o, vars);
      std::error_code ec;
      if (!fs::exists(p) || (fs::is_regular_file(p) && fs::file_size(p, ec) == 0))
        return "exit 0 without the output " + p.string();
    }
    if (!errors.empty()) return "exit 0 with an [error] line";
    return "";
  }
  if (r.exit_code != 2) return "exit code " + std::to_string(r.exit_code) + " (signal or crash?)";
  if (c.expect == Expect::kOk) return "exit 2 on good input";
  if (errors.size() != 1) return std::to_string(errors.size()) + " [error] lines instead of one";
  const std::string names = expand(c.names, vars);
  if (!names.empty() && errors[0].find(names) == std::string::npos) return "the [error] line does not name " + names;
  if (errors[0].size() > 2000) return "an [error] line of " + std::to_string(errors[0].size()) + " chars";
  for (const std::string& o : c.outputs) {
    const fs::path p = expand(o, vars);
    if (fs::exists(p)) return "failed but left " + p.string() + ", which looks complete";
  }
  return "";
}

// Runs every case with a fresh {out} folder under `scratch`, and fails once with the list of breaches, each with
// its command and output. `before` (optional) prepares a case, e.g. mutates a fixture file; `after` undoes it.
inline void runCliTable(const std::string& what, const std::vector<CliCase>& cases,
                        std::map<std::string, std::string> vars, const fs::path& scratch) {
  std::string report;
  std::size_t breaches = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path out = scratch / (what + "_" + std::to_string(i));
    fs::remove_all(out);
    fs::create_directories(out);
    vars["{out}"] = out.string();
    const std::string args = expand(cases[i].args, vars);
    const CliRun r = runCli(args, cases[i].timeout_s);
    const std::string breach = contractBreach(cases[i], r, vars);
    if (breach.empty()) continue;
    ++breaches;
    std::string shown = r.output.size() > 1500
                            ? r.output.substr(0, 700) + "\n...\n" + r.output.substr(r.output.size() - 700)
                            : r.output;
    report += "\n--- " + breach + " (exit " + std::to_string(r.exit_code) + ")\n  $ drover " + args + "\n" + shown;
  }
  std::cout << "[fuzz] cli " << what << ": " << cases.size() << " cases, " << breaches << " breaches\n";
  EXPECT_EQ(breaches, 0u) << what << ": commands that broke the CLI contract:" << report;
}

}  // namespace drover::test::fuzz
