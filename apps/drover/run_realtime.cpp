#include "apps/drover/run_realtime.hpp"

#include <pthread.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <queue>
#include <thread>
#include <vector>

#include "apps/drover/heap_tuning.hpp"

namespace drover::cli {
namespace {

using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;
constexpr std::size_t kReadAhead = 4000;  // measurements the reader thread may be ahead (~2 s of a 200 Hz IMU + sweeps)

// When the measurement would have reached the computer: a sweep once it is complete (its end), the rest at their
// stamps.
Time arrivalOf(const Measurement& m) {
  if (const auto* scan = std::get_if<LidarScan>(&m)) return std::max(scan->t, scan->t_end);
  return measurementTime(m);
}

// The reader in its own thread, a bounded number of measurements ahead of the pushes.
class ReadAhead {
 public:
  ReadAhead(io::Reader& reader, const StopOnSignal& stop)
      : thread_([this, &reader, &stop] {
          pthread_setname_np(pthread_self(), "drover-reader");
          run(reader, stop);
        }) {}
  ~ReadAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  std::optional<Measurement> next() {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !items_.empty() || done_; });
    if (items_.empty()) return std::nullopt;
    Measurement m = std::move(items_.front());
    items_.pop_front();
    changed_.notify_all();
    return m;
  }

 private:
  void run(io::Reader& reader, const StopOnSignal& stop) {
    for (;;) {
      std::optional<Measurement> m = stop.requested() ? std::nullopt : reader.next();
      std::unique_lock<std::mutex> lock(mutex_);
      if (!m) break;
      changed_.wait(lock, [this] { return items_.size() < kReadAhead || quit_; });
      if (quit_) break;
      items_.push_back(std::move(*m));
      changed_.notify_all();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
    changed_.notify_all();
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Measurement> items_;
  bool done_ = false, quit_ = false;
  std::thread thread_;  // last: started once the members above exist
};

// Latencies [ms], written from the System's threads.
struct Latencies {
  std::mutex mutex;
  std::map<Time, Clock::time_point> sweep_arrival;  // by the sweep's stamp on the IMU clock (ScanOutcome::t)
  BoundedQuantiles sweep_ms, imu_ms;
  double first_sweep_ms = -1;
  std::optional<Clock::time_point> first_pose;  // when the first sweep's pose was published
  std::size_t startup_sweeps = 0;               // sweeps after the first that arrived before it
  Clock::time_point imu_arrival;  // of the sample being pushed (the IMU-rate callback runs inside pushImu)
};

double msBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

}  // namespace

void runRealtime(io::Reader& reader, const pipeline::SystemConfig& config, const RealtimeOptions& o,
                 const StopOnSignal& stop, RealtimeRun& run) {
  Latencies lat;
  std::mutex record_mutex;
  pipeline::SystemCallbacks cb;
  cb.imu_odometry = [&lat, &run](const pipeline::ImuOdometry& p) {
    lat.imu_ms.add(msBetween(lat.imu_arrival, Clock::now()));  // the pushing thread: no lock needed
    if (run.record.imu_rate) run.record.imu_rate->add(p.t, p.T_world_imu);  // what a robot would have got
  };
  cb.sweep = [&](const pipeline::ScanOutcome& s) {
    const Clock::time_point now = Clock::now();
    {
      std::lock_guard<std::mutex> lock(lat.mutex);
      const auto it = lat.sweep_arrival.find(s.t);
      if (it != lat.sweep_arrival.end()) {
        // Start-up: the first pose waits for the IMU's initialisation window (~1 s of data after the first sweep),
        // and so does every sweep that arrived before it. Reported on their own, not as latencies of the running
        // system.
        const double ms = msBetween(it->second, now);
        if (!lat.first_pose) {
          lat.first_pose = now;
          lat.first_sweep_ms = ms;
        } else if (it->second < *lat.first_pose) {
          ++lat.startup_sweeps;
        } else {
          lat.sweep_ms.add(ms);
        }
        lat.sweep_arrival.erase(lat.sweep_arrival.begin(), std::next(it));
      }
    }
    if (!s.warning.empty()) spdlog::warn("sweep at {:.3f} s: {}", toSeconds(s.t), s.warning);
    if (!s.note.empty()) spdlog::info("sweep at {:.3f} s: {}", toSeconds(s.t), s.note);
    std::lock_guard<std::mutex> lock(record_mutex);
    run.record.add(s);
  };
  cb.loop = [](const pipeline::LoopCorrection& c) {
    spdlog::info("loop closed: keyframe {} with keyframe {} ({:.1f} s earlier), corrected by {:.2f} m", c.event.query,
                 c.event.candidate, toSeconds(c.event.t_query - c.event.t_candidate), c.event.correction);
  };
  cb.warning = [](const std::string& w) { spdlog::warn("{}", w); };
  if (o.vis != nullptr)
    cb.vis_frame = [&](const vio::VisFrame& f) {
      std::lock_guard<std::mutex> lock(record_mutex);
      o.vis->record(f);
    };
  run.system = std::make_unique<pipeline::System>(config, reader.calibration(), cb, o.detector);
  pipeline::System& system = *run.system;
  const Time lidar_offset = reader.calibration().lidar_time_offset;

  // Pushes in arrival order: a sweep is held until the measurements stamped before its end have gone.
  const auto cmp = [](const std::pair<Time, std::size_t>& a, const std::pair<Time, std::size_t>& b) { return a > b; };
  std::priority_queue<std::pair<Time, std::size_t>, std::vector<std::pair<Time, std::size_t>>, decltype(cmp)> held(cmp);
  std::map<std::size_t, Measurement> pending;
  std::size_t serial = 0;
  std::optional<Time> t_first, data_zero;
  Clock::time_point wall_zero;
  double late_ms_max = 0;
  HeapTrimmer heap;  // as the replay: the free pages returned every 30 s of data (apps/drover/heap_tuning.hpp)
  const auto pushDue = [&](Time up_to) {
    while (!held.empty() && held.top().first <= up_to) {
      const auto [arrival, id] = held.top();
      held.pop();
      Measurement m = std::move(pending.at(id));
      pending.erase(id);
      if (!data_zero) {
        data_zero = arrival;
        wall_zero = Clock::now();
      }
      const auto since = std::chrono::nanoseconds(static_cast<Time>(static_cast<double>(arrival - *data_zero) / o.rate));
      const Clock::time_point due = wall_zero + since;
      std::this_thread::sleep_until(due);
      late_ms_max = std::max(late_ms_max, msBetween(due, Clock::now()));
      heap.tick(arrival);
      if (auto* imu = std::get_if<ImuSample>(&m)) {
        lat.imu_arrival = due;
        system.pushImu(*imu);
      } else if (auto* scan = std::get_if<LidarScan>(&m)) {
        {
          std::lock_guard<std::mutex> lock(lat.mutex);
          lat.sweep_arrival[scan->t + lidar_offset] = due;
        }
        run.record.scan_times.push_back(scan->t + lidar_offset);
        system.pushSweep(std::move(*scan));
      } else {
        system.pushFrame(std::move(std::get<CameraFrame>(m)));
      }
    }
  };
  const Clock::time_point wall_start = Clock::now();
  {
    ReadAhead ahead(reader, stop);
    while (std::optional<Measurement> m = ahead.next()) {
      const Time t = measurementTime(*m);
      if (!t_first) t_first = t;
      const double since = toSeconds(t - *t_first);
      if (since < o.start) continue;
      if (o.duration > 0 && since > o.start + o.duration) {
        run.record.end = "--duration reached";
        break;
      }
      held.emplace(arrivalOf(*m), serial);
      pending.emplace(serial++, std::move(*m));
      pushDue(t);
    }
    pushDue(std::numeric_limits<Time>::max());
  }
  if (stop.requested()) run.record.end = "interrupted by " + signalName(stop.signal());
  system.shutdown();
  run.record.wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  run.record.data_s = run.record.sweeps > 1 ? toSeconds(run.record.last_t - run.record.first_t) : 0.0;
  const pipeline::SystemStats s = system.stats();
  if (o.vis != nullptr) o.vis->attach(system.vis(), s.frames_pushed, s.frames_bad);
  run.realtime = Json{{"latency_ms", {{"sweep", lat.sweep_ms.percentiles()}, {"imu_rate", lat.imu_ms.percentiles()}}},
                      {"rate", o.rate},
                      {"first_sweep_ms", lat.first_sweep_ms},
                      {"startup_sweeps", lat.startup_sweeps},
                      {"sweeps_dropped", s.sweeps_dropped},
                      {"frames_dropped", s.frames_dropped},
                      {"sweeps_pushed", s.sweeps_pushed},
                      {"loops_applied", s.loops_applied},
                      {"push_late_ms_max", late_ms_max},
                      {"sweep_queue", config.live.sweep_queue},
                      {"loop_rate_hz", config.live.loop_rate_hz}};
}

}  // namespace drover::cli
