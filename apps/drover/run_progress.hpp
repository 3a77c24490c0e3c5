#pragma once
// drover run's progress line on the console (apps/drover/cmd_run.cpp).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstddef>

namespace drover::cli {

// Prints "scan N, t / T s (p%), x real time, ETA" about every 2 s of wall time.
class RunProgress {
  using Clock = std::chrono::steady_clock;

 public:
  explicit RunProgress(double total_s) : total_s_(total_s), wall_start_(Clock::now()), last_(wall_start_) {}
  void update(std::size_t scans, double data_s) {
    const auto now = Clock::now();
    if (now - last_ < std::chrono::seconds(2)) return;
    last_ = now;
    const double rtf = data_s / std::max(1e-9, wallSeconds());
    if (total_s_ > 0) {
      const double eta = rtf > 0 ? std::max(0.0, total_s_ - data_s) / rtf : 0.0;
      spdlog::info("run: scan {}, {:.1f} / {:.1f} s ({:.0f}%), {:.1f}x real time, ETA {:.0f} s", scans, data_s, total_s_,
                   100.0 * std::min(1.0, data_s / total_s_), rtf, eta);
    } else {
      spdlog::info("run: scan {}, {:.1f} s of data, {:.1f}x real time", scans, data_s, rtf);
    }
  }
  double wallSeconds() const { return std::chrono::duration<double>(Clock::now() - wall_start_).count(); }

 private:
  double total_s_;
  Clock::time_point wall_start_, last_;
};

}  // namespace drover::cli
