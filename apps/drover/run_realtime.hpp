#pragma once
// drover run --realtime: the dataset replayed at sensor rate through the live system (pipeline::System), as a robot
// would feed it: each measurement is pushed when it would have arrived (a sweep at its end, IMU samples and frames
// at their stamps), late data is late, and a stage that falls behind drops sweeps. Reading runs ahead in its own
// thread so that decoding does not delay the pushes. Measures the latency of every output from the moment its data
// arrived: per sweep from the sweep's end to its published pose, per IMU sample to its IMU-rate pose.
#include <nlohmann/json.hpp>

#include <memory>

#include "apps/drover/run_folder.hpp"
#include "apps/drover/run_output.hpp"
#include "apps/drover/run_vis.hpp"
#include "io/reader.hpp"
#include "pipeline/system.hpp"

namespace drover::cli {

struct RealtimeOptions {
  double start = 0, duration = 0;  // [s] as drover run's --start / --duration (duration 0 = to the end)
  double rate = 1.0;  // [-] sensor seconds played per wall second (--rate; 0.5: half speed)
  std::shared_ptr<visual::KeypointDetector> detector;  // the VIS's, with config.vis
  RunVis* vis = nullptr;  // records the VIS's frames (with config.vis)
};

struct RealtimeRun {
  std::unique_ptr<pipeline::System> system;  // shut down: its state is ready to be written
  RunRecord record;  // the caller may stream its files first (streamRunFiles)
  nlohmann::json realtime;  // report.json "realtime": latency_ms {sweep, imu_rate} {p50, p95, max}, sweeps_dropped, ...
};

// Runs the whole dataset (or the --start/--duration window) through a System made from config; stops early when
// `stop` is signalled (run.record.end says so). The IMU-rate odometry the System publishes goes to
// run.record.imu_rate when it is set.
void runRealtime(io::Reader& reader, const pipeline::SystemConfig& config, const RealtimeOptions& options,
                 const StopOnSignal& stop, RealtimeRun& run);

}  // namespace drover::cli
