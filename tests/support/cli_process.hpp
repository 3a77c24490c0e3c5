#pragma once
// The drover binary run from a chosen working folder, and run in the background so a test can signal it.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/cli.hpp"
#include "support/temp_dir.hpp"

extern char** environ;

namespace drover::test {

// runDrover from CWD, with optional `NAME=value ...` environment assignments in front.
inline CliResult runDroverIn(const std::filesystem::path& cwd, const std::string& args, const std::string& env = "") {
  return runShell("cd '" + cwd.string() + "' && " + env + " " + DROVER_BINARY + " " + args + " 2>&1");
}

// drover started in the background with ARGS (split at spaces), its stdout and stderr going to LOG.
class DroverProcess {
 public:
  DroverProcess(const std::string& args, const std::filesystem::path& log) : log_(log) {
    std::istringstream in(args);
    for (std::string a; in >> a;) args_.push_back(a);
    std::vector<char*> argv{const_cast<char*>(DROVER_BINARY)};
    for (std::string& a : args_) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    if (posix_spawn(&pid_, DROVER_BINARY, &actions, nullptr, argv.data(), environ) != 0) pid_ = -1;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~DroverProcess() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      wait();
    }
  }
  DroverProcess(const DroverProcess&) = delete;
  DroverProcess& operator=(const DroverProcess&) = delete;

  bool started() const { return pid_ > 0; }
  bool running() {
    if (pid_ <= 0 || done_) return false;
    if (::waitpid(pid_, &status_, WNOHANG) == pid_) done_ = true;
    return !done_;
  }
  // Polls CONDITION every 0.2 ms while the process runs; true once it holds, false if the process ended first or
  // TIMEOUT passed.
  bool waitUntil(const std::function<bool()>& condition, std::chrono::seconds timeout = std::chrono::seconds(120)) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      if (condition()) return true;
      if (!running()) return condition();
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    return false;
  }
  bool logContains(const std::string& part) const { return contains(readText(log_), part); }
  void signal(int sig) { ::kill(pid_, sig); }
  // The raw wait status (WIFEXITED, WTERMSIG...).
  int wait() {
    if (!done_ && pid_ > 0 && ::waitpid(pid_, &status_, 0) == pid_) done_ = true;
    return status_;
  }
  std::string log() const { return readText(log_); }

 private:
  std::filesystem::path log_;
  std::vector<std::string> args_;
  pid_t pid_ = -1;
  int status_ = -1;
  bool done_ = false;
};

}  // namespace drover::test
