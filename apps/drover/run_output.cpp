#include "apps/drover/run_output.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <filesystem>
#include <numeric>

#include "apps/drover/eval_report.hpp"
#include "apps/drover/loop_report.hpp"
#include "apps/drover/run_vis.hpp"
#include "eval/ape.hpp"
#include "geometry/trajectory_fill.hpp"
#include "io/cloud_io.hpp"
#include "io/error.hpp"
#include "io/kitti_common.hpp"
#include "io/trajectory_io.hpp"

namespace drover::cli {
namespace {
namespace fs = std::filesystem;

constexpr float kMapLeaf = 0.2f;  // [m] voxel leaf of the exported map

std::string inRun(const RunContext& c, const char* name) { return (fs::path(c.dir) / name).string(); }

// T_world_lidar -> T_world_body for the ground truth's body frame ("imu": T_world_imu = T_world_lidar T_lidar_imu).
Trajectory inBodyFrame(const Trajectory& lidar, const RunContext& c) {
  if (c.ground_truth.body_frame != "imu") return lidar;
  const Eigen::Isometry3d T_lidar_imu = c.calibration.T_imu_lidar.inverse();
  Trajectory out = lidar;
  for (auto& p : out) p.T_world_body = p.T_world_body * T_lidar_imu;
  return out;
}

// T_imu_body of trajectory.tum's body frame: the IMU's, or the lidar's when the body is not the IMU.
Eigen::Isometry3d imuToBody(const RunContext& c) {
  return c.ground_truth.body_frame == "imu" ? Eigen::Isometry3d::Identity() : c.calibration.T_imu_lidar;
}

// KITTI devkit frame: T_cam0(0)_cam0(i) = Tr T_lidar0_lidar_i Tr^-1 with Tr = T_cam0_lidar from calib.txt. One line
// per scan read, as poses.txt and the devkit match by line: a sweep the odometry skipped gets the pose interpolated
// between its neighbours (extrapolated at the ends), with a warning; the JSON lists those scans (index, how).
Json writeKittiTrajectory(const RunContext& c, const Trajectory& lidar, const RunRecord& r) {
  if (c.format != "kitti" || lidar.empty()) return nullptr;
  const io::KittiCalibFile calib((fs::path(c.dataset) / "calib.txt").string());
  const Eigen::Isometry3d Tr = calib.rigid34("Tr");
  const std::vector<geometry::FilledPose> filled = geometry::posesAtTimes(lidar, r.scan_times);
  const Eigen::Isometry3d T_lidar0_world = filled.front().pose.T_world_body.inverse();
  Trajectory cam;
  Json fills = Json::array();
  std::string listed;
  for (std::size_t i = 0; i < filled.size(); ++i) {
    const geometry::FilledPose& f = filled[i];
    cam.push_back({f.pose.t, Tr * (T_lidar0_world * f.pose.T_world_body) * Tr.inverse()});
    if (f.kind == geometry::FillKind::kEstimated) continue;
    fills.push_back({{"line", i}, {"t", toSeconds(f.pose.t)}, {"pose", geometry::toString(f.kind)}});
    if (fills.size() <= 10) listed += fmt::format("{}{} ({})", listed.empty() ? "" : ", ", i, geometry::toString(f.kind));
  }
  io::writeKitti(inRun(c, "trajectory_kitti.txt"), cam);
  if (!fills.empty())
    spdlog::warn("trajectory_kitti.txt: {} of {} scans had no pose of their own (skipped sweeps); their lines "
                 "(0-based) hold a pose from their neighbours: {}{}",
                 fills.size(), filled.size(), listed, fills.size() > 10 ? ", ..." : "");
  return {{"lines", filled.size()}, {"filled", fills}};
}

Json timingsJson(const RunRecord& r) {
  Json j;
  for (std::size_t i = 0; i < r.stage_ms.size(); ++i) {
    const BoundedQuantiles& q = r.stage_ms[i];
    j[RunRecord::stageNames()[i]] = {{"mean_ms", q.mean()}, {"p95_ms", q.quantile(0.95)}, {"max_ms", q.max()}};
  }
  return j;
}

Json statsJson(const pipeline::OdometryStats& s, const RunRecord& r) {
  Json j;
  j["measurements_dropped"] = r.measurements_dropped;
  j["scans_in"] = s.scans_in;
  j["scans_processed"] = s.scans_processed;
  j["scans_skipped_empty"] = s.scans_skipped_empty;
  j["scans_skipped_time"] = s.scans_skipped_time;
  j["points_dropped"] = s.points_dropped;
  j["points_nonfinite"] = s.points_nonfinite;
  j["keyframes"] = s.keyframes;
  j["keyframes_retired"] = s.keyframes_retired;
  j["degenerate_scans"] = s.degenerate_scans;
  j["not_converged"] = s.not_converged;
  j["smoother_resets"] = s.smoother_resets;
  j["imu_scans"] = s.imu_scans;
  j["vis_guess_scans"] = s.vis_guess_scans;    // sweeps matched from the VIS's motion (LVI-SAM's initial guess)
  j["vis_factor_scans"] = s.vis_factor_scans;  // sweeps whose IMU smoother had the VIS's motion as a factor
  j["vis_resets_requested"] = s.vis_resets_requested;  // times the LIS asked a VIS its gates kept refusing to reset
  j["imu_initialized"] = s.imu_initialized;
  j["imu_init"] = s.imu_init;
  j["imu"] = {{"accepted", s.imu.accepted},
              {"gaps", s.imu.gaps},
              {"largest_gap_s", s.imu.largest_gap_s},
              {"dropped_nonfinite", s.imu.dropped_nonfinite},
              {"dropped_out_of_order", s.imu.dropped_out_of_order},
              {"dropped_spike", s.imu.dropped_spike}};
  Json deg = Json::array(), resets = Json::array(), restarts = Json::array();
  for (Time t : s.map_restart_times) restarts.push_back(toSeconds(t));
  for (Time t : s.degenerate_times) deg.push_back(toSeconds(t));
  for (Time t : s.reset_times) resets.push_back(toSeconds(t));
  j["degenerate_times_s"] = deg;
  j["reset_times_s"] = resets;
  j["map_restart_times_s"] = restarts;
  j["notices"] = s.notices;
  return j;
}

// Translation APE after SE(3) alignment, associated within 10 ms (evo's default).
eval::ApeOptions se3ApeOptions() {
  eval::ApeOptions options;
  options.alignment = eval::Alignment::kSe3;
  options.association.max_diff = 10'000'000;  // [ns]
  return options;
}

// APE of the translation with SE(3) alignment (and the rotation angle), printed as evo prints it.
Json evaluate(const RunContext& c, const Trajectory& est) {
  if (c.ground_truth.poses.empty() || est.size() < 3) return nullptr;
  eval::ApeOptions options = se3ApeOptions();
  Json j;
  try {
    const eval::ApeResult r = eval::computeApe(c.ground_truth.poses, est, options);
    if (spdlog::should_log(spdlog::level::info)) fmt::print("{}\n\n{}\n", apeTitle(r), statisticsTable(r.stats));
    j = statisticsJson(r.stats);
    j["pairs"] = r.pairs;
    options.relation = eval::PoseRelation::kAngleDeg;
    j["rotation_deg"] = statisticsJson(eval::computeApe(c.ground_truth.poses, est, options).stats);
    io::writeFileAtomically(inRun(c, "ape.json"), j.dump(2) + "\n");
    std::vector<std::size_t> all(r.pairs);
    std::iota(all.begin(), all.end(), 0);
    writePlot(plotData(apeTitle(r), eval::relationUnit(r.relation), r.times, r.errors, r.est_aligned, all,
                       c.ground_truth.poses, r.association.first),
              inRun(c, "ape.png"));
  } catch (const std::invalid_argument& e) {
    spdlog::warn("APE not computed: {}", e.what());
    j = {{"error", e.what()}};
  }
  return j;
}

// The IMU-rate odometry (streamed during the run) finished into the folder: its count, rate [Hz] and, with ground
// truth, its own SE(3)-aligned translation APE [m] (the file is read back for it).
Json finishImuRate(const RunContext& c, RunRecord& r) {
  if (!r.imu_rate) return nullptr;
  const std::string path = inRun(c, "trajectory_imu_rate.tum");
  const ImuRateFile::Summary s = r.imu_rate->copyTo(path);
  r.imu_rate.reset();  // drover run's stream is closed here
  Json j = {{"poses", s.poses}};
  if (s.poses == 0) fs::remove(path);
  if (s.poses < 3) return j;
  j["rate_hz"] = static_cast<double>(s.poses - 1) / toSeconds(s.last - s.first);
  if (c.ground_truth.poses.empty()) return j;
  try {
    j["ape"] = statisticsJson(eval::computeApe(c.ground_truth.poses, io::readTum(path), se3ApeOptions()).stats);
  } catch (const std::invalid_argument& e) {
    j["ape"] = {{"error", e.what()}};
  }
  return j;
}

double pathLength(const Trajectory& poses) {  // [m]
  double length = 0;
  for (std::size_t k = 1; k < poses.size(); ++k)
    length += (poses[k].T_world_body.translation() - poses[k - 1].T_world_body.translation()).norm();
  return length;
}

// report.json's "vis" section: the VIS's counts and means and, with ground truth, its own translation APE
// (SE(3)-aligned) of `est`, trajectory_vis.tum as written, printed as evo does.
Json visSection(const RunContext& c, const RunVis& vis, const Trajectory& est) {
  Json j = vis.report();
  if (est.size() < 3 || c.ground_truth.poses.empty()) return j;
  try {
    const eval::ApeResult a = eval::computeApe(c.ground_truth.poses, est, se3ApeOptions());
    if (spdlog::should_log(spdlog::level::info)) fmt::print("VIS {}\n\n{}\n", apeTitle(a), statisticsTable(a.stats));
    j["ape"] = statisticsJson(a.stats);
    const double length = pathLength(c.ground_truth.poses);
    if (length > 0) j["ape"]["rmse_percent_of_path"] = 100.0 * a.stats.rmse / length;
  } catch (const std::invalid_argument& e) {
    j["ape"] = {{"error", e.what()}};
  }
  return j;
}

// Beside the LIS: the VIS's streamed files finished into the folder, its trajectory read back only to be evaluated.
Json finishVisFiles(const RunContext& c, RunVis& vis) {
  const ImuRateFile::Summary s = vis.finishFiles();
  const bool evaluated = s.poses >= 3 && !c.ground_truth.poses.empty();
  return visSection(c, vis, evaluated ? io::readTum(inRun(c, "trajectory_vis.tum")) : Trajectory{});
}

}  // namespace

void writeVisRunFolder(const RunContext& c, RunVis& vis, const RunRecord& r) {
  Json report;
  report["dataset"] = c.dataset;
  report["format"] = c.format;
  report["config"] = c.config;
  report["preset"] = c.preset;
  report["mode"] = "camera+imu";
  report["end"] = {{"reason", r.end}, {"interrupted", r.end.rfind("interrupted", 0) == 0}};
  report["body_frame"] = c.ground_truth.body_frame.empty() ? "imu" : c.ground_truth.body_frame;
  report["wall_s"] = r.wall_s;
  vis.finishFiles();  // trajectory_vis.tum complete from here
  const std::string vis_path = inRun(c, "trajectory_vis.tum"), path = inRun(c, "trajectory.tum");
  std::error_code e;  // trajectory.tum is the VIS's here, byte for byte
  fs::copy_file(vis_path, path, fs::copy_options::overwrite_existing, e);
  if (e) throw io::IoError(path, "", "cannot copy the VIS trajectory from " + vis_path + ": " + e.message());
  const Trajectory est = io::readTum(path);  // read once, for both APEs
  const double data_s = est.size() > 1 ? toSeconds(est.back().t - est.front().t) : 0.0;
  report["data_s"] = data_s;
  report["real_time_factor"] = r.wall_s > 0 ? data_s / r.wall_s : 0.0;
  report["counts"] = {{"measurements_dropped", r.measurements_dropped}};
  report["ape"] = evaluate(c, est);
  report["vis"] = visSection(c, vis, est);
  io::writeFileAtomically(inRun(c, "report.json"), report.dump(2) + "\n");
  spdlog::info("VIS: {} of {} camera frames estimated, {} resets, in {:.1f} s: {:.1f}x real time; results in {}",
               est.size(), vis.framesIn(), report["vis"]["resets"].get<std::size_t>(), r.wall_s,
               r.wall_s > 0 ? data_s / r.wall_s : 0.0, c.out);
}

void streamVisFiles(const RunContext& c, RunVis& vis) {
  vis.streamTo(inRun(c, "vis_frames.jsonl"), inRun(c, "trajectory_vis.tum"), imuToBody(c));
}

void streamRunFiles(const RunContext& c, RunRecord& r, bool imu) {
  r.log.streamTo(inRun(c, "sweeps.jsonl"));
  if (!imu) return;
  r.imu_rate = std::make_shared<ImuRateFile>(inRun(c, "trajectory_imu_rate.tum"), imuToBody(c));
}

void writeRunFolder(const RunContext& c, const pipeline::LidarOdometry& odometry, RunRecord& r, RunVis* vis,
                    const LiveRun* live) {
  const Trajectory est = inBodyFrame(odometry.trajectory(), c);
  if (!est.empty()) {
    io::writeTum(inRun(c, "trajectory.tum"), est);
    io::writeTum(inRun(c, "keyframes.tum"), inBodyFrame(odometry.keyframeTrajectory(), c));
  }
  const Json kitti = writeKittiTrajectory(c, odometry.trajectory(), r);
  r.log.finish(inRun(c, "sweeps.jsonl"));
  const lidar::PointCloud map = odometry.mapCloud(kMapLeaf);
  io::writePcdBinary(inRun(c, "map.pcd"), map);
  io::writePlyBinary(inRun(c, "map.ply"), map);

  const pipeline::OdometryStats& s = odometry.stats();
  Json report;
  report["dataset"] = c.dataset;
  report["format"] = c.format;
  report["config"] = c.config;
  report["preset"] = c.preset;
  report["mode"] = s.imu_initialized ? "lidar+imu" : "lidar";  // what was fused (the IMU may have been given up)
  report["imu_requested"] = odometry.config().use_imu;
  report["end"] = {{"reason", r.end}, {"interrupted", r.end.rfind("interrupted", 0) == 0}};
  report["body_frame"] = c.ground_truth.body_frame.empty() ? "lidar" : c.ground_truth.body_frame;
  report["wall_s"] = r.wall_s;
  report["data_s"] = r.data_s;
  report["real_time_factor"] = r.wall_s > 0 ? r.data_s / r.wall_s : 0.0;
  report["map_points"] = map.size();
  report["counts"] = statsJson(s, r);
  report["timings"] = timingsJson(r);
  report["ape"] = evaluate(c, est);
  const bool live_loops = live != nullptr && live->loops != nullptr;
  report["loops"] = loopsJson(c, odometry, live_loops ? *live->loops : odometry.loopClosure());
  if (live != nullptr && !live->realtime.is_null()) report["realtime"] = live->realtime;
  if (odometry.config().use_imu) report["imu_rate"] = finishImuRate(c, r);
  if (!kitti.is_null()) report["trajectory_kitti"] = kitti;
  if (vis != nullptr) report["vis"] = finishVisFiles(c, *vis);
  report["mode"] = std::string(report["mode"]) + (vis != nullptr && vis->framesEstimated() > 0 ? "+camera" : "");
  report["sweeps_logged"] = r.log.lines();  // sweeps.jsonl's lines
  io::writeFileAtomically(inRun(c, "report.json"), report.dump(2) + "\n");
  spdlog::info("{} sweeps ({} keyframes, {} degenerate, {} resets) in {:.1f} s: {:.1f}x real time; results in {}",
               s.scans_processed, s.keyframes, s.degenerate_scans, s.smoother_resets, r.wall_s,
               r.wall_s > 0 ? r.data_s / r.wall_s : 0.0, c.out);
}

}  // namespace drover::cli
