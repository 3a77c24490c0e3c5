#pragma once
// A private ROS1 graph for a test: a master on a free port with ROS_HOME and ROS_LOG_DIR in the test's temporary
// folder, and child processes (the master, the node, rosbag play) each leading its own process group. Every guard
// kills its group in its destructor, whatever happened in the test (a failed ASSERT, an exception), and each leader
// is also killed by the kernel when the test process dies (PR_SET_PDEATHSIG), so no master, node or player outlives
// the test.
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace drover::test {

// A TCP port nobody listens on now (the kernel's pick for port 0; another process could take it before the master
// does, which a test run on a busy machine reports as a master that did not start).
inline int freePort() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t n = sizeof(a);
  int port = -1;
  if (s >= 0 && ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0 &&
      ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &n) == 0)
    port = ntohs(a.sin_port);
  if (s >= 0) ::close(s);
  return port;
}

// A child process leading its own process group, stdout and stderr to `log`. The destructor sends the group
// SIGINT, waits up to 5 s, then SIGKILLs it.
class ChildGroup {
 public:
  ChildGroup(const std::vector<std::string>& argv, const std::filesystem::path& log) : log_(log) {
    // Everything the child needs is prepared here: after fork() only async-signal-safe calls (this process has
    // ROS threads).
    const std::string program = resolve(argv.at(0));
    std::vector<std::string> copy = argv;
    std::vector<char*> args;
    for (std::string& a : copy) args.push_back(a.data());
    args.push_back(nullptr);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const pid_t parent = ::getpid();
    pid_ = fd < 0 || program.empty() ? -1 : ::fork();
    if (pid_ == 0) {
      ::setpgid(0, 0);                      // its own group: the kill reaches whatever it starts
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);   // and the leader dies with the test, even a SIGKILLed one
      if (::getppid() != parent) ::_exit(127);
      // An ignored signal stays ignored across exec (a test run from a background shell ignores SIGINT): the
      // child must hear the SIGINT it is stopped with.
      ::signal(SIGINT, SIG_DFL);
      ::signal(SIGTERM, SIG_DFL);
      ::dup2(fd, 1);
      ::dup2(fd, 2);
      ::execve(program.c_str(), args.data(), environ);
      ::_exit(127);
    }
    if (pid_ > 0) ::setpgid(pid_, pid_);  // also here, so a signal sent right away finds the group
    if (fd >= 0) ::close(fd);
  }
  ~ChildGroup() { stop(std::chrono::seconds(5)); }
  ChildGroup(const ChildGroup&) = delete;
  ChildGroup& operator=(const ChildGroup&) = delete;

  bool started() const { return pid_ > 0; }
  bool running() {
    if (pid_ <= 0 || done_) return false;
    if (::waitpid(pid_, &status_, WNOHANG) == pid_) done_ = true;
    return !done_;
  }
  void signal(int sig) {
    if (pid_ > 0) ::kill(-pid_, sig);
  }
  // Waits for the leader to exit; false on timeout.
  bool waitExit(std::chrono::milliseconds timeout) {
    const auto end = std::chrono::steady_clock::now() + timeout;
    while (running()) {
      if (std::chrono::steady_clock::now() > end) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return true;
  }
  // The exit code, -1 while running or when a signal ended it.
  int exitCode() {
    if (running()) return -1;
    return WIFEXITED(status_) ? WEXITSTATUS(status_) : -1;
  }
  // SIGINT to the group, then SIGKILL after `grace`; reaps the leader. Idempotent.
  void stop(std::chrono::milliseconds grace) {
    if (pid_ <= 0) return;
    if (running()) {
      signal(SIGINT);
      if (!waitExit(grace)) {
        signal(SIGKILL);
        waitExit(std::chrono::seconds(5));
      }
    }
    ::kill(-pid_, SIGKILL);  // anything the leader left behind in its group
  }
  std::string log() const {
    std::ifstream in(log_);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }

 private:
  // PROGRAM as execvp would find it on PATH ("" when nowhere).
  static std::string resolve(const std::string& program) {
    if (program.find('/') != std::string::npos) return program;
    const char* path = std::getenv("PATH");
    std::stringstream dirs(path ? path : "/usr/bin:/bin");
    for (std::string d; std::getline(dirs, d, ':');)
      if (::access((d + "/" + program).c_str(), X_OK) == 0) return d + "/" + program;
    return "";
  }

  std::filesystem::path log_;
  pid_t pid_ = -1;
  int status_ = 0;
  bool done_ = false;
};

// The environment of a private graph, set for this process and its children: ROS_MASTER_URI on a free port,
// ROS_HOSTNAME on the loopback, ROS_HOME and ROS_LOG_DIR under `dir`.
inline int privateRosEnvironment(const std::filesystem::path& dir) {
  const int port = freePort();
  std::filesystem::create_directories(dir / "ros_home");
  std::filesystem::create_directories(dir / "ros_log");
  ::setenv("ROS_MASTER_URI", ("http://127.0.0.1:" + std::to_string(port)).c_str(), 1);
  ::setenv("ROS_HOSTNAME", "127.0.0.1", 1);
  ::unsetenv("ROS_IP");
  ::setenv("ROS_HOME", (dir / "ros_home").c_str(), 1);
  ::setenv("ROS_LOG_DIR", (dir / "ros_log").c_str(), 1);
  return port;
}

}  // namespace drover::test
