// drover info: stream a whole dataset once and summarise it (per-sensor counts, times and rates, calibration,
// ground truth), as text on stdout and optionally as JSON; optionally export the ground truth as TUM.
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "apps/drover/checked_options.hpp"
#include "apps/drover/commands.hpp"
#include "io/config.hpp"
#include "io/dataset.hpp"
#include "io/output_paths.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::cli {
namespace {

using Json = nlohmann::ordered_json;

struct InfoOptions {
  std::string dataset;
  std::string format;
  std::string config;
  std::string json;
  std::string export_gt;
  std::size_t max_frames = 0;
};

// Count, first and last stamp of one sensor's stream.
struct StreamStats {
  std::size_t count = 0;
  Time first = 0;  // [ns]
  Time last = 0;   // [ns]

  void add(Time t) {
    if (count == 0) first = t;
    last = t;
    ++count;
  }
  double spanSeconds() const { return toSeconds(last - first); }
  // (count - 1) intervals over the span [Hz]; 0 when fewer than two stamps.
  double meanRateHz() const { return count >= 2 && last > first ? static_cast<double>(count - 1) / spanSeconds() : 0; }
};

struct Summary {
  StreamStats imu, lidar, camera;
  std::size_t imu_with_orientation = 0;
  double lidar_points = 0;  // summed over scans
  std::size_t lidar_with_time = 0, lidar_with_ring = 0;
  std::size_t lidar_nonfinite = 0, scans_with_nonfinite = 0;  // points the reader dropped for NaN/inf values
  int width = 0, height = 0, channels = 0;  // of the first image
  bool image_size_varies = false;
};

void addMeasurement(Summary& s, const Measurement& m) {
  if (const auto* imu = std::get_if<ImuSample>(&m)) {
    s.imu.add(imu->t);
    s.imu_with_orientation += imu->q_world_imu.has_value() ? 1 : 0;
  } else if (const auto* scan = std::get_if<LidarScan>(&m)) {
    s.lidar.add(scan->t);
    s.lidar_points += static_cast<double>(scan->points.size());
    s.lidar_with_time += scan->has_time ? 1 : 0;
    s.lidar_with_ring += scan->has_ring ? 1 : 0;
    s.lidar_nonfinite += scan->dropped_nonfinite;
    s.scans_with_nonfinite += scan->dropped_nonfinite > 0 ? 1 : 0;
  } else if (const auto* frame = std::get_if<CameraFrame>(&m)) {
    if (s.camera.count == 0) {
      s.width = frame->image.width, s.height = frame->image.height, s.channels = frame->image.channels;
    } else if (frame->image.width != s.width || frame->image.height != s.height) {
      s.image_size_varies = true;
    }
    s.camera.add(frame->t);
  }
}

Summary streamDataset(io::Reader& reader) {
  Summary s;
  Time previous = 0;
  std::size_t index = 0, notices_shown = 0;
  const auto showDrops = [&] {
    for (; notices_shown < reader.drops().notices.size(); ++notices_shown)
      spdlog::warn("{}", reader.drops().notices[notices_shown]);
  };
  while (const auto m = reader.next()) {
    showDrops();
    const Time t = measurementTime(*m);
    // Readers promise non-decreasing time; a violation is a reader bug that would corrupt any run.
    if (index > 0 && t < previous)
      throw std::runtime_error(fmt::format("{}: measurement {} at {} s comes before the previous one at {} s",
                                           reader.describe(), index, io::formatSeconds(t),
                                           io::formatSeconds(previous)));
    addMeasurement(s, *m);
    previous = t;
    ++index;
  }
  showDrops();
  if (s.lidar_nonfinite > 0)
    spdlog::warn("{} non-finite lidar points dropped (in {} of {} scans)", s.lidar_nonfinite, s.scans_with_nonfinite,
                 s.lidar.count);
  return s;
}

double pathLength(const Trajectory& poses) {
  double length = 0;
  for (std::size_t i = 1; i < poses.size(); ++i)
    length += (poses[i].T_world_body.translation() - poses[i - 1].T_world_body.translation()).norm();
  return length;
}

Json streamJson(const StreamStats& s) {
  Json j;
  j["count"] = s.count;
  j["first_time_ns"] = s.first;
  j["last_time_ns"] = s.last;
  j["span_s"] = s.spanSeconds();
  j["mean_rate_hz"] = s.meanRateHz();
  return j;
}

Json rowMajor(const Eigen::Isometry3d& T) {
  Json j = Json::array();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) j.push_back(T.matrix()(r, c));
  return j;
}

Json calibrationJson(const Calibration& c) {
  Json j;
  j["T_imu_lidar"] = rowMajor(c.T_imu_lidar);
  j["T_imu_cam"] = rowMajor(c.T_imu_cam);
  const CameraIntrinsics& k = c.camera;
  j["camera"] = {{"width", k.width}, {"height", k.height}, {"fx", k.fx},
                 {"fy", k.fy},       {"cx", k.cx},         {"cy", k.cy},
                 {"distortion_model", distortionModelName(k.distortion)}, {"distortion_coeffs", k.distortion_coeffs}};
  j["lidar_time_offset_s"] = toSeconds(c.lidar_time_offset);
  j["camera_time_offset_s"] = toSeconds(c.camera_time_offset);
  return j;
}

Json summaryJson(const InfoOptions& o, const io::Reader& reader, const Summary& s) {
  Json j;
  j["dataset"] = o.dataset;
  j["format"] = o.format;
  j["description"] = reader.describe();
  j["imu"] = streamJson(s.imu);
  j["imu"]["with_orientation"] = s.imu_with_orientation;
  j["lidar"] = streamJson(s.lidar);
  j["lidar"]["mean_points_per_scan"] = s.lidar.count ? s.lidar_points / static_cast<double>(s.lidar.count) : 0.0;
  j["lidar"]["scans_with_time"] = s.lidar_with_time;
  j["lidar"]["scans_with_ring"] = s.lidar_with_ring;
  j["lidar"]["points_nonfinite_dropped"] = s.lidar_nonfinite;
  j["measurements_dropped"] = reader.drops().measurements;
  j["camera"] = streamJson(s.camera);
  j["camera"]["width"] = s.width;
  j["camera"]["height"] = s.height;
  j["camera"]["channels"] = s.channels;
  j["camera"]["size_varies"] = s.image_size_varies;
  j["calibration"] = calibrationJson(reader.calibration());
  const io::GroundTruth& gt = reader.groundTruth();
  Json g;
  g["count"] = gt.poses.size();
  g["body_frame"] = gt.body_frame;
  g["first_time_ns"] = gt.poses.empty() ? 0 : gt.poses.front().t;
  g["last_time_ns"] = gt.poses.empty() ? 0 : gt.poses.back().t;
  g["span_s"] = gt.poses.empty() ? 0.0 : toSeconds(gt.poses.back().t - gt.poses.front().t);
  g["path_length_m"] = pathLength(gt.poses);
  j["ground_truth"] = g;
  return j;
}

std::string streamLine(const char* name, const StreamStats& s, const char* unit) {
  if (s.count == 0) return fmt::format("{:<13}none\n", name);
  return fmt::format("{:<13}{} {}, {} .. {} s ({:.3f} s), {:.3f} Hz\n", name, s.count, unit,
                     io::formatSeconds(s.first), io::formatSeconds(s.last), s.spanSeconds(), s.meanRateHz());
}

std::string matrixLines(const char* name, const Eigen::Isometry3d& T) {
  std::string out = fmt::format("  {}:\n", name);
  for (int r = 0; r < 3; ++r)
    out += fmt::format("    [{:12.8f} {:12.8f} {:12.8f} | {:10.5f}]\n", T(r, 0), T(r, 1), T(r, 2), T(r, 3));
  return out;
}

std::string summaryText(const Json& j, const Summary& s, const io::Reader& reader) {
  std::string out = fmt::format("Dataset:     {} ({}, format {})\n", reader.describe(), j["dataset"].get<std::string>(),
                                j["format"].get<std::string>());
  out += streamLine("IMU:", s.imu, "samples");
  if (s.imu_with_orientation) out += fmt::format("             {} with orientation\n", s.imu_with_orientation);
  out += streamLine("Lidar:", s.lidar, "scans");
  if (s.lidar.count)
    out += fmt::format("             {:.1f} points per scan; per-point time in {}/{} scans, ring in {}/{}\n",
                       j["lidar"]["mean_points_per_scan"].get<double>(), s.lidar_with_time, s.lidar.count,
                       s.lidar_with_ring, s.lidar.count);
  if (s.lidar_nonfinite)
    out += fmt::format("             {} non-finite points dropped (in {} scans)\n", s.lidar_nonfinite,
                       s.scans_with_nonfinite);
  out += streamLine("Camera:", s.camera, "frames");
  if (s.camera.count)
    out += fmt::format("             {}x{} px, {} channel(s){}\n", s.width, s.height, s.channels,
                       s.image_size_varies ? " (size varies)" : "");
  if (reader.drops().measurements)
    out += fmt::format("Dropped:     {} measurements (a repeated or backwards stamp, or an unusable reading)\n",
                       reader.drops().measurements);
  const Calibration& c = reader.calibration();
  out += "Calibration:\n" + matrixLines("T_imu_lidar", c.T_imu_lidar) + matrixLines("T_imu_cam", c.T_imu_cam);
  const CameraIntrinsics& k = c.camera;
  out += fmt::format("  camera: {}x{} px, fx {} fy {} cx {} cy {} [px], {} [{}]\n", k.width, k.height, k.fx, k.fy,
                     k.cx, k.cy, distortionModelName(k.distortion), fmt::join(k.distortion_coeffs, ", "));
  out += fmt::format("  time offsets: lidar {} s, camera {} s\n", io::formatSeconds(c.lidar_time_offset),
                     io::formatSeconds(c.camera_time_offset));
  const Json& g = j["ground_truth"];
  if (g["count"].get<std::size_t>() == 0) return out + "Ground truth: none\n";
  return out + fmt::format("Ground truth: {} poses of '{}', {} .. {} s ({:.3f} s), path length {:.3f} m\n",
                           g["count"].get<std::size_t>(), g["body_frame"].get<std::string>(),
                           io::formatSeconds(g["first_time_ns"].get<Time>()),
                           io::formatSeconds(g["last_time_ns"].get<Time>()), g["span_s"].get<double>(),
                           g["path_length_m"].get<double>());
}

void runInfo(const InfoOptions& o) {
  io::checkOutputFile(o.json, "--json");  // before streaming the dataset, which can take minutes
  io::checkOutputFile(o.export_gt, "--export-gt");
  io::DatasetOptions options = o.config.empty() ? io::DatasetOptions{} : io::loadDatasetOptions(o.config);
  if (o.max_frames > 0) options.kitti_max_frames = o.max_frames;
  const std::unique_ptr<io::Reader> reader = io::openDataset(o.dataset, o.format, options);
  if (!o.export_gt.empty() && reader->groundTruth().poses.empty())
    throw std::runtime_error(o.dataset + ": the dataset has no ground truth to export to " + o.export_gt);
  const Summary summary = streamDataset(*reader);
  const Json j = summaryJson(o, *reader, summary);
  if (spdlog::should_log(spdlog::level::info)) fmt::print("{}", summaryText(j, summary, *reader));  // -q: --json only
  if (!o.json.empty()) io::writeFileAtomically(o.json, j.dump(2) + "\n");
  if (!o.export_gt.empty()) io::writeTum(o.export_gt, reader->groundTruth().poses);
}

}  // namespace

void registerInfo(CLI::App& app) {
  auto* cmd = app.add_subcommand("info", "Summarise a dataset's measurement stream, calibration and ground truth");
  auto o = std::make_shared<InfoOptions>();
  cmd->add_option("dataset", o->dataset,
                  "Dataset folder (KITTI sequence/drive, EuRoC sequence, drover sim output) or bag file")
      ->required();
  cmd->add_option("--format", o->format, "Dataset format")
      ->required()
      ->check(CLI::IsMember({"kitti", "kitti-raw", "euroc", "bag", "sim"}));
  cmd->add_option("--config", o->config, "Platform config (config/*.yaml): topics, sensors to load, calibration");
  cmd->add_option("--json", o->json, "Also write the summary as JSON to this file");
  cmd->add_option("--export-gt", o->export_gt, "Write the ground truth (T_world_body) as a TUM file");
  addInteger(cmd, "--max-frames", o->max_frames, 1, 1'000'000'000,
             "KITTI odometry: read only the first N >= 1 frames (default: all)");
  cmd->callback([o] { runInfo(*o); });
}

}  // namespace drover::cli
