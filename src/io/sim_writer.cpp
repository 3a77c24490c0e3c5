// Writer of Drover's simulated-dataset folder (format in io/sim_dataset.hpp).
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "io/error.hpp"
#include "io/sim_dataset.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

static_assert(std::endian::native == std::endian::little, "the .bin records are written in host order");

std::string calibrationYaml(const SimDatasetDescription& d) {
  const Calibration& c = d.calibration;
  const CameraIntrinsics& k = c.camera;
  const SimSensorInfo& s = d.sensors;
  std::string y = "# Drover simulated dataset: calibration and sensor settings (format: src/io/sim_dataset.hpp).\n";
  y += "calibration:\n";
  y += "  T_imu_lidar: " + formatRowMajor(c.T_imu_lidar) + "  # row-major 4x4, lidar -> IMU [m]\n";
  y += "  T_imu_cam: " + formatRowMajor(c.T_imu_cam) + "  # row-major 4x4, camera -> IMU [m]\n";
  y += "  lidar_time_offset: " + formatSeconds(c.lidar_time_offset) + "  # [s], t_imu = t_lidar + offset\n";
  y += "  camera_time_offset: " + formatSeconds(c.camera_time_offset) + "  # [s], t_imu = t_camera + offset\n";
  y += "  camera:\n";
  y += "    width: " + std::to_string(k.width) + "  # [px]\n";
  y += "    height: " + std::to_string(k.height) + "  # [px]\n";
  y += "    fx: " + formatDouble(k.fx) + "  # [px]\n    fy: " + formatDouble(k.fy) + "  # [px]\n";
  y += "    cx: " + formatDouble(k.cx) + "  # [px]\n    cy: " + formatDouble(k.cy) + "  # [px]\n";
  y += std::string("    distortion_model: ") + distortionModelName(k.distortion) + "\n";
  y += "    distortion_coeffs: " + formatNumberList(k.distortion_coeffs) + "\n";
  y += "sensors:\n";
  y += "  lidar:\n    model: " + s.lidar_model + "\n    rings: " + std::to_string(s.lidar_rings) +
       "\n    columns: " + std::to_string(s.lidar_columns) + "  # firings per revolution\n    rate_hz: " +
       formatDouble(s.lidar_rate_hz) + "  # [Hz]\n";
  y += "  camera:\n    rate_hz: " + formatDouble(s.camera_rate_hz) + "  # [Hz]\n    channels: " +
       std::to_string(s.camera_channels) + "  # 1 = mono8, 3 = bgr8\n    exposure_s: " +
       formatDouble(s.camera_exposure_s) + "  # [s]\n    pixel_samples: " + std::to_string(s.camera_pixel_samples) +
       "  # rays per pixel side (1: the pixel's centre only)\n    texture_filter: " +
       std::string(s.camera_texture_filter ? "true" : "false") + "  # textures averaged over each ray's footprint\n" +
       "    edge_pixel_samples: " + std::to_string(s.camera_edge_pixel_samples) +
       "  # rays per pixel side where the pixel's rays disagree (0: off)\n";
  y += "  imu:\n    rate_hz: " + formatDouble(s.imu_rate_hz) + "  # [Hz]\n";
  y += "    gyro_noise_density: " + formatDouble(s.gyro_noise_density) + "  # [rad/s/sqrt(Hz)]\n";
  y += "    accel_noise_density: " + formatDouble(s.accel_noise_density) + "  # [m/s^2/sqrt(Hz)]\n";
  y += "    gyro_bias_random_walk: " + formatDouble(s.gyro_bias_random_walk) + "  # [rad/s^2/sqrt(Hz)]\n";
  y += "    accel_bias_random_walk: " + formatDouble(s.accel_bias_random_walk) + "  # [m/s^3/sqrt(Hz)]\n";
  y += "  ground_truth:\n    rate_hz: " + formatDouble(s.ground_truth_rate_hz) + "  # [Hz]\n    body_frame: imu\n";
  return y;
}

std::string scenarioJson(const SimDatasetDescription& d) {
  const SimScenarioInfo& s = d.scenario;
  nlohmann::ordered_json j;
  j["format_version"] = kSimFormatVersion;
  j["generator"] = s.generator;
  j["scenario"] = s.name;
  j["seed"] = s.seed;
  j["duration_s"] = s.duration_s;
  j["path_length_m"] = s.path_length_m;
  j["closes_loop"] = s.closes_loop;
  j["lidar_model"] = d.sensors.lidar_model;
  j["sensors"] = {{"imu", s.has_imu}, {"lidar", s.has_lidar}, {"camera", s.has_camera}};
  j["segments"] = nlohmann::ordered_json::array();
  for (const SimSegmentInfo& seg : s.segments)
    j["segments"].push_back({{"condition", seg.condition}, {"start_ns", seg.start}, {"end_ns", seg.end}});
  // Only with faults, so that a dataset without them stays byte-identical to one from before faults existed.
  for (const SimSegmentInfo& f : s.faults)
    j["faults"].push_back({{"kind", f.condition}, {"start_ns", f.start}, {"end_ns", f.end}});
  return j.dump(2) + "\n";
}

void requireLater(Time previous, Time t, std::size_t count, const char* what) {
  if (count > 0 && t <= previous)
    throw std::invalid_argument(std::string("sim writer: ") + what + " " + std::to_string(count) + " at " +
                                formatSeconds(t) + " s is not after the previous one at " + formatSeconds(previous) +
                                " s");
}

// One 24-byte record (layout in sim_dataset.hpp).
void packPoint(const LidarPoint& p, std::uint32_t offset_ns, char* out) {
  const std::uint16_t reserved = 0;
  std::memcpy(out + 0, &p.x, 4);
  std::memcpy(out + 4, &p.y, 4);
  std::memcpy(out + 8, &p.z, 4);
  std::memcpy(out + 12, &p.intensity, 4);
  std::memcpy(out + 16, &offset_ns, 4);
  std::memcpy(out + 20, &p.ring, 2);
  std::memcpy(out + 22, &reserved, 2);
}

void writeBinary(const fs::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) fail(path.string(), "", "cannot create file");
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out.flush()) fail(path.string(), "", "write failed (disk full?)");
}

StagingRules simStagingRules(const SimWriterOptions& options) {
  StagingRules rules;
  rules.may_replace = options.overwrite;
  rules.replace_hint = "use --force to replace it";
  rules.replaceable = simDatasetProblem;
  rules.refusal = "--force replaces only an earlier simulated dataset";
  return rules;
}

}  // namespace

std::string simFileName(std::size_t index, const char* extension) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06zu%s", index, extension);
  return buf;
}

void SimDatasetWriter::checkOutput(const std::string& dir, const SimWriterOptions& options) {
  StagedFolder::check(dir, simStagingRules(options));
}

SimDatasetWriter::SimDatasetWriter(const std::string& dir, const SimDatasetDescription& description,
                                   const SimWriterOptions& options)
    : description_(description), options_(options) {
  if (options.png_compression < 0 || options.png_compression > 9)
    throw std::invalid_argument("sim writer: png_compression must be 0..9, got " +
                                std::to_string(options.png_compression));
  if (description.sensors.camera_channels != 1 && description.sensors.camera_channels != 3)
    throw std::invalid_argument("sim writer: camera channels must be 1 or 3, got " +
                                std::to_string(description.sensors.camera_channels));
  staged_ = std::make_unique<StagedFolder>(dir, simStagingRules(options));
  dir_ = staged_->out();
  partial_ = staged_->dir();
  std::error_code ec;
  fs::create_directories(partial_ / "lidar", ec);
  if (!ec) fs::create_directories(partial_ / "camera", ec);
  if (ec) fail(partial_.string(), "", "cannot create folder: " + ec.message());
  lidar_csv_ = "# index,t_start_ns,t_end_ns\n";
  camera_csv_ = "# index,t_ns\n";
  encoder_ = std::thread([this] { encoderLoop(); });
}

SimDatasetWriter::~SimDatasetWriter() {
  stopEncoder();
  staged_.reset();  // unless finished, removes DIR.partial (after the encoder stopped writing into it)
}

void SimDatasetWriter::add(Measurement&& m) {
  if (finished_) throw std::logic_error("sim writer: add() after finish()");
  rethrowEncoderError();
  if (auto* imu = std::get_if<ImuSample>(&m)) return addImu(*imu);
  if (auto* scan = std::get_if<LidarScan>(&m)) return addScan(*scan);
  addFrame(std::move(std::get<CameraFrame>(m)));
}

void SimDatasetWriter::addImu(const ImuSample& s) {
  requireLater(last_imu_, s.t, counts_.imu, "IMU sample");
  if (counts_.imu > 0 && s.q_world_imu.has_value() != imu_has_orientation_)
    throw std::invalid_argument("sim writer: IMU sample " + std::to_string(counts_.imu) +
                                " differs from the first in carrying an orientation");
  imu_has_orientation_ = s.q_world_imu.has_value();
  if (!s.omega_imu.allFinite() || !s.acc_imu.allFinite() || (s.q_world_imu && !s.q_world_imu->coeffs().allFinite()))
    throw std::invalid_argument("sim writer: IMU sample " + std::to_string(counts_.imu) + " is not finite");
  std::string line = std::to_string(s.t);
  for (double v : {s.omega_imu.x(), s.omega_imu.y(), s.omega_imu.z(), s.acc_imu.x(), s.acc_imu.y(), s.acc_imu.z()})
    line.append(1, ',').append(formatDouble(v));
  if (s.q_world_imu)
    for (double v : {s.q_world_imu->w(), s.q_world_imu->x(), s.q_world_imu->y(), s.q_world_imu->z()})
      line.append(1, ',').append(formatDouble(v));
  imu_csv_ += line + "\n";
  last_imu_ = s.t;
  ++counts_.imu;
}

void SimDatasetWriter::addScan(const LidarScan& scan) {
  requireLater(last_lidar_, scan.t, counts_.lidar, "lidar scan");
  const std::string name = "lidar scan " + std::to_string(counts_.lidar);
  if (scan.t_end < scan.t) throw std::invalid_argument("sim writer: " + name + " ends before it starts");
  const Time span = scan.t_end - scan.t;
  std::string bytes(scan.points.size() * kSimPointBytes, '\0');
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const LidarPoint& p = scan.points[i];
    const double offset_ns = std::round(static_cast<double>(p.time_offset) * 1e9);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(p.intensity) ||
        !(offset_ns >= 0 && offset_ns <= static_cast<double>(span)))
      throw std::invalid_argument("sim writer: " + name + " point " + std::to_string(i) +
                                  " is not finite or its time offset is outside the sweep");
    if (p.ring >= description_.sensors.lidar_rings)
      throw std::invalid_argument("sim writer: " + name + " point " + std::to_string(i) + " has ring " +
                                  std::to_string(p.ring) + " >= rings " +
                                  std::to_string(description_.sensors.lidar_rings));
    packPoint(p, static_cast<std::uint32_t>(offset_ns), bytes.data() + i * kSimPointBytes);
  }
  writeBinary(partial_ / "lidar" / simFileName(counts_.lidar, ".bin"), bytes);
  lidar_csv_ += std::to_string(counts_.lidar) + "," + std::to_string(scan.t) + "," + std::to_string(scan.t_end) + "\n";
  last_lidar_ = scan.t;
  ++counts_.lidar;
  counts_.lidar_points += scan.points.size();
}

void SimDatasetWriter::addFrame(CameraFrame&& frame) {
  requireLater(last_camera_, frame.t, counts_.camera, "camera frame");
  const CameraIntrinsics& k = description_.calibration.camera;
  const Image& img = frame.image;
  if (img.width != k.width || img.height != k.height || img.channels != description_.sensors.camera_channels ||
      img.data.size() != static_cast<std::size_t>(img.width) * img.height * img.channels)
    throw std::invalid_argument("sim writer: camera frame " + std::to_string(counts_.camera) + " is " +
                                std::to_string(img.width) + "x" + std::to_string(img.height) + "x" +
                                std::to_string(img.channels) + ", calibration says " + std::to_string(k.width) + "x" +
                                std::to_string(k.height) + "x" + std::to_string(description_.sensors.camera_channels));
  camera_csv_ += std::to_string(counts_.camera) + "," + std::to_string(frame.t) + "\n";
  PendingImage pending{partial_ / "camera" / simFileName(counts_.camera, ".png"), std::move(frame.image)};
  {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return queue_.size() < options_.max_queued_images || !encoder_error_.empty(); });
    queue_.push_back(std::move(pending));
  }
  cv_.notify_all();
  last_camera_ = frame.t;
  ++counts_.camera;
}

void SimDatasetWriter::encoderLoop() {
  const std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, options_.png_compression};
  while (true) {
    PendingImage item;
    {
      std::unique_lock lock(mutex_);
      cv_.wait(lock, [&] { return !queue_.empty() || stop_; });
      if (queue_.empty()) return;  // stop_ and drained
      item = std::move(queue_.front());
      queue_.pop_front();
    }
    cv_.notify_all();
    std::string error;
    try {
      Image& img = item.image;
      const cv::Mat mat(img.height, img.width, img.channels == 1 ? CV_8UC1 : CV_8UC3, img.data.data());
      if (!cv::imwrite(item.path.string(), mat, params)) error = item.path.string() + ": cannot write PNG";
    } catch (const cv::Exception& e) {
      error = item.path.string() + ": cannot write PNG: " + e.what();
    }
    if (!error.empty()) {
      std::lock_guard lock(mutex_);
      if (encoder_error_.empty()) encoder_error_ = error;
      queue_.clear();
      cv_.notify_all();
    }
  }
}

void SimDatasetWriter::stopEncoder() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (encoder_.joinable()) encoder_.join();
}

void SimDatasetWriter::rethrowEncoderError() {
  std::lock_guard lock(mutex_);
  if (!encoder_error_.empty()) throw IoError(encoder_error_, "", "image encoding failed");
}

void SimDatasetWriter::finish(const Trajectory& ground_truth) {
  if (finished_) throw std::logic_error("sim writer: finish() called twice");
  stopEncoder();
  rethrowEncoderError();
  writeTum((partial_ / "groundtruth.txt").string(), ground_truth);
  std::string imu_header = "# t_ns,wx,wy,wz [rad/s],ax,ay,az [m/s^2] (IMU frame)";
  imu_header += imu_has_orientation_ ? ",qw,qx,qy,qz (q_world_imu)\n" : "\n";
  writeFileAtomically((partial_ / "imu.csv").string(), imu_header + imu_csv_);
  writeFileAtomically((partial_ / "lidar" / "timestamps.csv").string(), lidar_csv_);
  writeFileAtomically((partial_ / "camera" / "timestamps.csv").string(), camera_csv_);
  writeFileAtomically((partial_ / "scenario.json").string(), scenarioJson(description_));
  // calibration.yaml last: a folder holding it was written completely.
  writeFileAtomically((partial_ / "calibration.yaml").string(), calibrationYaml(description_));
  staged_->publish();
  finished_ = true;
}

}  // namespace drover::io
