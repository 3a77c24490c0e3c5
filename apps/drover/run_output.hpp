#pragma once
// What `drover run` writes into its run folder (names that scripts rely on):
//   trajectory.tum        one pose per sweep, T_world_body with body = the ground truth's body frame (the IMU for
//                         simulated and IMU datasets, the lidar for KITTI odometry), TUM format
//   trajectory_kitti.txt  KITTI odometry only: one line per scan read (a skipped sweep gets a pose interpolated
//                         between its neighbours, or extrapolated at the ends), camera-0 frame, first pose identity
//   keyframes.tum         the keyframes' poses, same frame as trajectory.tum
//   trajectory_imu_rate.tum  with the IMU: the IMU-rate odometry (the fused state propagated to each IMU sample as
//                         it arrives), same frame as trajectory.tum; streamed while the run goes (RunRecord::imu_rate)
//   sweeps.jsonl          one JSON line per processed sweep (match, features, biases, ms); streamed likewise
//   trajectory_vis.tum    with a camera and an IMU: the VIS estimate at every camera frame after its initialisation,
//                         same body frame as trajectory.tum (with --no-lidar trajectory.tum is this trajectory)
//   map.pcd, map.ply      the keyframes' clouds in the world frame (binary)
//   report.json           how the run ended, counts, per-stage timings, degenerate sweeps, resets, and the APE when there is ground truth
//   ape.json, ape.png     APE (translation, SE(3)-aligned) against the ground truth, when there is one
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "apps/drover/run_record.hpp"
#include "io/reader.hpp"
#include "pipeline/lidar_odometry.hpp"

namespace drover::cli {
class RunVis;
}

namespace drover::cli {

struct RunContext {
  std::string dataset, format, config, out;
  const Calibration& calibration;
  const io::GroundTruth& ground_truth;
  std::string dir;  // where the files are written: OUT.partial, renamed to `out` when complete
  std::string preset = "platform";  // drover run --preset (run_preset.hpp)
};

// A --realtime run (pipeline::System): its loop thread's loop closure and report.json's "realtime" section.
struct LiveRun {
  const pipeline::LoopClosure* loops = nullptr;
  nlohmann::json realtime;
};

// Writes every file above (each atomically) and prints the APE table. Throws IoError when a file cannot be
// written.
// vis: the VIS when it ran beside the LIS (nullptr otherwise); live: set for a --realtime run.
// record.log, record.imu_rate and the VIS's streamed files are finished into the folder (closed, or copied there
// when streamed elsewhere).
void writeRunFolder(const RunContext& context, const pipeline::LidarOdometry& odometry, RunRecord& record,
                    RunVis* vis, const LiveRun* live = nullptr);
// Before a run: its per-sweep lines and (with the IMU) its IMU-rate odometry streamed into context.dir.
void streamRunFiles(const RunContext& context, RunRecord& record, bool imu);
// Before the VIS's first frame: its per-frame lines (vis_frames.jsonl) and its trajectory (trajectory_vis.tum, in
// trajectory.tum's body frame) streamed into context.dir.
void streamVisFiles(const RunContext& context, RunVis& vis);
// --no-lidar: the VIS alone (trajectory.tum, trajectory_vis.tum, vis_frames.jsonl, report.json, ape.json/png).
void writeVisRunFolder(const RunContext& context, RunVis& vis, const RunRecord& record);

}  // namespace drover::cli
