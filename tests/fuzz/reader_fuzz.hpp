#pragma once
// In-process reader fuzzing. A target writes a small valid fixture, names the files to mutate and how to read
// everything; each case mutates one file (mutate.hpp), reads in a forked child (so a crash or a hang is reported as
// a failing case instead of ending the suite) and checks the readers' contract:
//   - the read succeeds, and what it returns is sane (time order, finite values: never silently wrong data), or
//   - it throws io::IoError whose message is one short line naming a file of the fixture;
//   - never another exception type (std::bad_alloc included: the child runs under a 2 GiB address-space limit),
//     never a signal, never longer than kCaseTimeout.
// A case is a number: seed and case number give the same mutation on every machine.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <typeinfo>
#include <variant>
#include <vector>

#include "fuzz/mutate.hpp"
#include "io/error.hpp"
#include "io/reader.hpp"
#include "support/temp_dir.hpp"

namespace drover::test::fuzz {
namespace fs = std::filesystem;

constexpr double kCaseTimeout = 10.0;              // [s] a reader slower than this on a tiny fixture hangs
constexpr std::size_t kMaxMessageChars = 2000;     // an error line is bounded (io::IoError's parts)
constexpr rlim_t kChildAddressSpace = 2ull << 30;  // [bytes]

enum class Outcome { kOk, kIoError, kWrong, kOtherException, kSignal, kHang };

inline const char* outcomeName(Outcome o) {
  switch (o) {
    case Outcome::kOk:
      return "ok";
    case Outcome::kIoError:
      return "IoError";
    case Outcome::kWrong:
      return "SILENTLY WRONG";
    case Outcome::kOtherException:
      return "OTHER EXCEPTION";
    case Outcome::kSignal:
      return "SIGNAL";
    case Outcome::kHang:
      return "HANG";
  }
  return "?";
}

struct CaseResult {
  Outcome outcome = Outcome::kOk;
  std::string message;
};

// One case of a campaign: write `bytes` to `path`, run the body, put `original` back.
struct FuzzCase {
  std::string path, bytes, original;
};

namespace detail {
inline void writeAll(int fd, const std::string& s) {
  for (std::size_t done = 0; done < s.size();) {
    const ssize_t n = write(fd, s.data() + done, s.size() - done);
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}
inline void putFile(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}
// The child: runs cases [first, end) in turn and sends one record per case: index (8 bytes), outcome code (1),
// message length (4), message. Its stderr goes to /dev/null (libpng's chatter is not the contract).
[[noreturn]] inline void childLoop(int fd, const std::vector<FuzzCase>& cases, std::size_t first, std::size_t end,
                                   const std::function<std::string()>& body) {
  const int devnull = open("/dev/null", O_WRONLY);
  if (devnull >= 0) dup2(devnull, STDERR_FILENO);
  const rlimit limit{kChildAddressSpace, kChildAddressSpace};
  setrlimit(RLIMIT_AS, &limit);
  for (std::size_t k = first; k < end; ++k) {
    putFile(cases[k].path, cases[k].bytes);
    char code = 'O';
    std::string message;
    try {
      message = body();
      if (!message.empty()) code = 'W';
    } catch (const io::IoError& e) {
      code = 'E', message = e.what();
    } catch (const std::exception& e) {
      code = 'X', message = std::string(typeid(e).name()) + ": " + e.what();
    } catch (...) {
      code = 'X', message = "unknown exception type";
    }
    putFile(cases[k].path, cases[k].original);
    if (message.size() > 64 * 1024)
      message = message.substr(0, 64 * 1024) + "... (" + std::to_string(message.size()) + " chars)";
    std::string record(13, '\0');
    const std::uint64_t index = k;
    const std::uint32_t length = static_cast<std::uint32_t>(message.size());
    std::memcpy(record.data(), &index, 8);
    record[8] = code;
    std::memcpy(record.data() + 9, &length, 4);
    writeAll(fd, record + message);
  }
  _exit(0);
}
}  // namespace detail

// Runs every case in forked children, up to `batch` cases per child so that forking is paid rarely. A child that
// dies (signal) or stops answering for kCaseTimeout is blamed on the case it was running; the next child goes on
// after it. `body` returns "" when what it read is sane, else what is wrong. Results are in case order.
inline std::vector<CaseResult> runCases(const std::vector<FuzzCase>& cases, const std::function<std::string()>& body,
                                        std::size_t batch = 64, double timeout_s = kCaseTimeout) {
  std::vector<CaseResult> results(cases.size());
  std::size_t next = 0;
  while (next < cases.size()) {
    const std::size_t end = std::min(cases.size(), next + batch);
    int fds[2];
    if (pipe(fds) != 0) {
      results[next++] = {Outcome::kOtherException, "pipe() failed"};
      continue;
    }
    std::cout.flush();
    const pid_t pid = fork();
    if (pid == 0) {
      close(fds[0]);
      detail::childLoop(fds[1], cases, next, end, body);
    }
    close(fds[1]);
    std::string buf;
    auto last = std::chrono::steady_clock::now();
    bool hung = false;
    for (;;) {
      const double idle = std::chrono::duration<double>(std::chrono::steady_clock::now() - last).count();
      if (idle > timeout_s) {
        hung = true;
        break;
      }
      pollfd p{fds[0], POLLIN, 0};
      if (poll(&p, 1, 200) <= 0) continue;
      char chunk[65536];
      const ssize_t n = read(fds[0], chunk, sizeof(chunk));
      if (n <= 0) break;
      buf.append(chunk, static_cast<std::size_t>(n));
      for (;;) {  // complete records
        if (buf.size() < 13) break;
        std::uint64_t index;
        std::uint32_t length;
        std::memcpy(&index, buf.data(), 8);
        std::memcpy(&length, buf.data() + 9, 4);
        if (buf.size() < 13 + length) break;
        const char code = buf[8];
        const std::string message = buf.substr(13, length);
        buf.erase(0, 13 + length);
        results[index] = {code == 'O'   ? Outcome::kOk
                          : code == 'W' ? Outcome::kWrong
                          : code == 'E' ? Outcome::kIoError
                                        : Outcome::kOtherException,
                          message};
        next = index + 1;
        last = std::chrono::steady_clock::now();
      }
    }
    close(fds[0]);
    if (hung) kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    if (next < end) {  // the child died or hung in case `next`, which it may have left mutated
      results[next] =
          hung ? CaseResult{Outcome::kHang, "no result after " + std::to_string(timeout_s) + " s"}
               : CaseResult{Outcome::kSignal, WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status))
                                                                  : "child ended without a result"};
      detail::putFile(cases[next].path, cases[next].original);
      ++next;
    }
  }
  return results;
}

// The Reader contract on what it returns: non-decreasing times, finite lidar points and IMU values, images whose
// buffer matches their size, finite ground truth in strictly increasing time. "" when all hold.
inline std::string checkStream(io::Reader& reader, bool check_camera_intrinsics) {
  std::ostringstream wrong;
  for (const StampedPose& p : reader.groundTruth().poses)
    if (!p.T_world_body.matrix().allFinite()) return "ground truth pose at " + std::to_string(p.t) + " not finite";
  const auto& gt = reader.groundTruth().poses;
  for (std::size_t i = 1; i < gt.size(); ++i)
    if (gt[i].t <= gt[i - 1].t) return "ground truth times not increasing at pose " + std::to_string(i);
  Time last = std::numeric_limits<Time>::min();
  std::size_t count = 0, frames = 0;
  while (auto m = reader.next()) {
    const Time t = measurementTime(*m);
    if (t < last) return "measurement " + std::to_string(count) + " goes back in time";
    last = t;
    if (const auto* s = std::get_if<LidarScan>(&*m)) {
      for (const LidarPoint& p : s->points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity) ||
            (s->has_time && !std::isfinite(p.time_offset)))
          return "scan at " + std::to_string(s->t) + " holds a non-finite point";
      if (s->t_end < s->t) return "scan at " + std::to_string(s->t) + " ends before it starts";
    } else if (const auto* imu = std::get_if<ImuSample>(&*m)) {
      if (!imu->omega_imu.allFinite() || !imu->acc_imu.allFinite())
        return "IMU sample at " + std::to_string(imu->t) + " not finite";
    } else if (const auto* f = std::get_if<CameraFrame>(&*m)) {
      ++frames;
      const Image& im = f->image;
      if (im.width <= 0 || im.height <= 0 ||
          im.data.size() != static_cast<std::size_t>(im.width) * im.height * im.channels)
        return "image at " + std::to_string(f->t) + " has a buffer that does not match its size";
    }
    if (++count > 1'000'000) return "more than a million measurements from a tiny fixture";
  }
  const CameraIntrinsics& k = reader.calibration().camera;
  if (check_camera_intrinsics && frames > 0 && !(k.fx > 0 && k.fy > 0 && std::isfinite(k.cx) && std::isfinite(k.cy)))
    return "camera frames with intrinsics fx " + std::to_string(k.fx) + " fy " + std::to_string(k.fy);
  return "";
}

struct FuzzFile {
  std::string rel;  // relative to the fixture root
  bool binary = false;
  std::size_t record = 1;  // record size of a binary file [bytes]
};

// A hand-made mutation, tried before the random ones, with what its IoError must (not) say.
struct ExtraCase {
  std::string file;  // relative to the fixture root
  Mutation mutation;
  std::string must_name = "";     // the IoError message must contain this
  std::string must_not_say = "";  // ... and not this (e.g. "missing" for a key that is present but malformed)
};

struct ReaderTarget {
  std::string name;
  std::function<void(const fs::path& root)> write_fixture;
  std::vector<FuzzFile> files;
  // Reads everything under root; returns "" or what is silently wrong; throws on bad input.
  std::function<std::string(const fs::path& root)> read;
  std::vector<ExtraCase> extra;  // e.g. a PNG header claiming a huge image
};

// Case k of a target: which file, which mutation.
inline std::pair<std::size_t, Mutation> caseMutation(const ReaderTarget& t, const std::vector<std::string>& originals,
                                                     std::uint64_t seed, std::size_t k) {
  Rng rng(seed * 1'000'003ull + k);
  const std::size_t f = rng.below(t.files.size());
  const FuzzFile& file = t.files[f];
  return {f, file.binary ? mutateBinary(originals[f], rng, file.record) : mutateText(originals[f], rng)};
}

// What groups failures into one report line: the message without the fixture's path, digits collapsed and cut
// before any quoted value, so that one bug seen on many lines or values is reported once per file and kind.
inline std::string failureClass(const std::string& message, const std::string& root) {
  std::string m = message.substr(0, 200);
  if (m.rfind(root, 0) == 0) m = m.substr(root.size());
  std::string out;
  for (char c : m) {
    if (c >= '0' && c <= '9') {
      if (out.empty() || out.back() != '#') out += '#';
    } else {
      out += c;
    }
  }
  return out.substr(0, std::min<std::size_t>(60, out.find('\'')));  // without the quoted value
}

// Runs `cases` random cases (fewer when the fixture's first batch shows they would take more than `budget_s`) plus
// the target's extra ones, and fails the test with one line per distinct failure: the file, the mutation and the
// outcome.
inline void runCampaign(const ReaderTarget& t, std::size_t cases, double budget_s = 15.0,
                        std::uint64_t seed = 20261124) {
  TempDir dir;
  const fs::path root = dir / "fixture";
  t.write_fixture(root);
  std::vector<std::string> originals;
  for (const FuzzFile& f : t.files) {
    std::ifstream in(root / f.rel, std::ios::binary);
    ASSERT_TRUE(in.good()) << "fixture file missing: " << (root / f.rel);
    originals.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto readRoot = [&] { return t.read(root); };
  // Once in this process first: it loads and initialises the libraries (OpenCV, yaml-cpp) before the children are
  // forked, which makes each case much cheaper.
  try {
    const std::string wrong = t.read(root);
    ASSERT_EQ(wrong, "") << t.name << ": the unmutated fixture must read cleanly";
  } catch (const std::exception& e) {
    FAIL() << t.name << ": the unmutated fixture must read cleanly: " << e.what();
  }
  std::vector<FuzzCase> list;
  std::vector<std::string> labels;
  std::vector<const ExtraCase*> extras;
  const auto add = [&](std::size_t f, const Mutation& m, const std::string& label, const ExtraCase* extra) {
    list.push_back({(root / t.files[f].rel).string(), m.bytes, originals[f]});
    labels.push_back(label + " [" + t.files[f].rel + ": " + m.description + "]");
    extras.push_back(extra);
  };
  for (std::size_t e = 0; e < t.extra.size(); ++e) {
    std::size_t f = 0;
    while (f < t.files.size() && t.files[f].rel != t.extra[e].file) ++f;
    ASSERT_LT(f, t.files.size()) << "extra mutation of an unknown file " << t.extra[e].file;
    add(f, t.extra[e].mutation, "extra " + std::to_string(e), &t.extra[e]);
  }
  for (std::size_t k = 0; k < cases; ++k) {
    const auto [f, m] = caseMutation(t, originals, seed, k);
    add(f, m, "case " + std::to_string(k) + " (seed " + std::to_string(seed) + ")", nullptr);
  }
  // Bound the time: measure one batch, then keep as many cases as fit in the budget.
  const auto start = std::chrono::steady_clock::now();
  const std::size_t probe = std::min<std::size_t>(list.size(), t.extra.size() + 32);
  std::vector<CaseResult> results =
      runCases(std::vector<FuzzCase>(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(probe)), readRoot);
  const double per_case = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / probe;
  const std::size_t fit = std::min(list.size(), probe + static_cast<std::size_t>(budget_s / std::max(per_case, 1e-6)));
  const std::vector<CaseResult> rest = runCases(std::vector<FuzzCase>(list.begin() + static_cast<std::ptrdiff_t>(probe),
                                                                      list.begin() + static_cast<std::ptrdiff_t>(fit)),
                                                readRoot);
  results.insert(results.end(), rest.begin(), rest.end());
  std::map<std::string, std::string> failures;  // distinct (why + message) -> the first case showing it
  std::map<Outcome, std::size_t> counts;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const CaseResult& r = results[i];
    const ExtraCase* extra = extras[i];
    ++counts[r.outcome];
    std::string why;
    if (r.outcome == Outcome::kIoError) {
      if (r.message.find(root.string()) == std::string::npos)
        why = "IoError names no file of the input";
      else if (r.message.find('\n') != std::string::npos)
        why = "IoError message spans several lines";
      else if (r.message.size() > kMaxMessageChars)
        why = "IoError message of " + std::to_string(r.message.size()) + " chars";
      else if (extra && r.message.find(extra->must_name) == std::string::npos)
        why = "IoError does not say " + extra->must_name;
      else if (extra && !extra->must_not_say.empty() && r.message.find(extra->must_not_say) != std::string::npos)
        why = "IoError says '" + extra->must_not_say + "'";
    } else if (r.outcome != Outcome::kOk) {
      why = outcomeName(r.outcome);
    }
    if (why.empty()) continue;
    const std::string shown = r.message.size() > 300 ? r.message.substr(0, 300) + "..." : r.message;
    const std::string key = why + ": " + failureClass(r.message, root.string());
    if (!failures.count(key)) failures[key] = t.name + " " + labels[i] + " -> " + why + ": " + shown;
  }
  std::cout << "[fuzz] " << t.name << ": " << results.size() - t.extra.size() << " of " << cases << " cases + "
            << t.extra.size() << " extra in "
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() << " s; ok "
            << counts[Outcome::kOk] << ", IoError " << counts[Outcome::kIoError] << ", " << failures.size()
            << " distinct failures\n";
  std::string report;
  for (const auto& [key, line] : failures) report += "  " + line + "\n";
  EXPECT_TRUE(failures.empty()) << t.name << ": the reader broke its contract:\n" << report;
}

}  // namespace drover::test::fuzz
