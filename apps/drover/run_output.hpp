#pragma once
// What `drover run` writes into its run folder (names that scripts rely on):
//   trajectory.tum        one pose per sweep, T_world_body with body = the ground truth's body frame (the IMU for
//                         simulated and IMU datasets, the lidar for KITTI odometry), TUM format
//   trajectory_kitti.txt  KITTI odometry only: one line per scan read (a skipped sweep gets a pose interpolated
//                         between its neighbours, or extrapolated at the ends), camera-0 frame, first pose identity
//   keyframes.tum         the keyframes' poses, same frame as trajectory.tum
//   trajectory_imu_rate.tum  with the IMU: the IMU-rate odometry (the fused state propagated to each IMU sample as
//                         it arrives), same frame as trajectory.tum
//   trajectory_vis.tum    with a camera and an IMU: the VIS estimate at every camera frame after its initialisation,
//                         same body frame as trajectory.tum (with --no-lidar trajectory.tum is this trajectory)
//   map.pcd, map.ply      the keyframes' clouds in the world frame (binary)
//   report.json           how the run ended, counts, per-stage timings, degenerate sweeps, resets, and the APE when there is ground truth
//   ape.json, ape.png     APE (translation, SE(3)-aligned) against the ground truth, when there is one
#include <string>
#include <vector>

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
};

struct RunRecord {
  std::vector<pipeline::ScanOutcome> scans;
  std::vector<Time> scan_times;  // [ns] every sweep handed to the odometry, on the IMU clock (as trajectory times)
  double wall_s = 0;  // [s] wall time of the odometry loop (reading included)
  double data_s = 0;  // [s] time spanned by the processed sweeps
  std::size_t notices_shown = 0;  // OdometryStats::notices already printed
  bool fusion_announced = false;  // the "fusing: ..." line was printed
  std::size_t reader_notices_shown = 0;  // io::ReaderDrops::notices already printed
  std::size_t measurements_dropped = 0;  // by the reader: a repeated or backwards stamp, or an unusable reading
  // Why the run stopped (report.json "end"): "end of data", "--duration reached", "--max-frames reached" or
  // "interrupted by SIGINT" / "SIGTERM".
  std::string end = "end of data";
};

// Writes every file above (each atomically) and prints the APE table. Throws IoError when a file cannot be
// written.
// vis: the VIS when it ran beside the LIS (nullptr otherwise). loops: the loop search when it ran away from the LIS
// (pipeline::System's loop thread); nullptr = the LIS's own (odometry.loopClosure()).
void writeRunFolder(const RunContext& context, const pipeline::LidarOdometry& odometry, const RunRecord& record,
                    const RunVis* vis, const pipeline::LoopClosure* loops = nullptr);
// --no-lidar: the VIS alone (trajectory.tum, trajectory_vis.tum, report.json, ape.json/png).
void writeVisRunFolder(const RunContext& context, const RunVis& vis, const RunRecord& record);

}  // namespace drover::cli
