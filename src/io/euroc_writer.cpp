// Writer of a simulated dataset in EuRoC's ASL layout (io/euroc_writer.hpp).
#include "io/euroc_writer.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "io/error.hpp"
#include "io/text_parsing.hpp"
#include "io/trajectory_io.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;

constexpr const char* kScenarioFile = "scenario.json";

std::string tbsYaml(const Eigen::Isometry3d& T) {
  return "T_BS:\n  cols: 4\n  rows: 4\n  data: " + formatRowMajor(T) + "\n";
}

std::string imuYaml(const SimSensorInfo& s) {
  std::string y = "%YAML:1.0\n# Drover simulated IMU (drover sim --format euroc)\nsensor_type: imu\n";
  y += "comment: simulated IMU, noise as below\n";
  y += tbsYaml(Eigen::Isometry3d::Identity());
  y += "rate_hz: " + formatDouble(s.imu_rate_hz) + "\n";
  y += "gyroscope_noise_density: " + formatDouble(s.gyro_noise_density) + "     # [ rad / s / sqrt(Hz) ]\n";
  y += "gyroscope_random_walk: " + formatDouble(s.gyro_bias_random_walk) + "       # [ rad / s^2 / sqrt(Hz) ]\n";
  y += "accelerometer_noise_density: " + formatDouble(s.accel_noise_density) + "  # [ m / s^2 / sqrt(Hz) ]\n";
  y += "accelerometer_random_walk: " + formatDouble(s.accel_bias_random_walk) + "    # [ m / s^3 / sqrt(Hz) ]\n";
  return y;
}

std::string cameraYaml(const SimDatasetDescription& d) {
  const CameraIntrinsics& k = d.calibration.camera;
  std::string y = "%YAML:1.0\n# Drover simulated camera (drover sim --format euroc)\nsensor_type: camera\n";
  y += "comment: simulated mono8 camera\n";
  y += tbsYaml(d.calibration.T_imu_cam);  // EuRoC's body frame is the IMU's
  y += "rate_hz: " + formatDouble(d.sensors.camera_rate_hz) + "\n";
  y += "resolution: [" + std::to_string(k.width) + ", " + std::to_string(k.height) + "]\n";
  y += "camera_model: pinhole\n";
  y += "intrinsics: " + formatNumberList({k.fx, k.fy, k.cx, k.cy}) + " #fu, fv, cu, cv\n";
  y += "distortion_model: radial-tangential\n";
  std::vector<double> coeffs = k.distortion_coeffs;
  if (k.distortion == DistortionModel::kNone) coeffs = {0, 0, 0, 0};
  y += "distortion_coefficients: " + formatNumberList(coeffs) + "\n";
  return y;
}

std::string scenarioJson(const SimScenarioInfo& s, const SimSensorInfo& sensors) {
  nlohmann::ordered_json j;
  j["generator"] = s.generator;
  j["format"] = "euroc";
  j["scenario"] = s.name;
  j["seed"] = s.seed;
  j["duration_s"] = s.duration_s;
  j["path_length_m"] = s.path_length_m;
  j["closes_loop"] = s.closes_loop;
  j["camera_pixel_samples"] = sensors.camera_pixel_samples;  // rays per pixel side the frames were rendered with
  j["camera_texture_filter"] = sensors.camera_texture_filter;
  j["camera_edge_pixel_samples"] = sensors.camera_edge_pixel_samples;  // 0: every pixel with the same rays
  return j.dump(2) + "\n";
}

std::string truthLine(const EurocTruthState& s) {
  const Eigen::Quaterniond q = canonicalQuaternion(s.T_world_imu.linear());
  const Eigen::Vector3d& p = s.T_world_imu.translation();
  std::string line = std::to_string(s.t);
  for (double v : {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), s.v_world.x(), s.v_world.y(), s.v_world.z(),
                   s.gyro_bias.x(), s.gyro_bias.y(), s.gyro_bias.z(), s.accel_bias.x(), s.accel_bias.y(),
                   s.accel_bias.z()})
    line.append(1, ',').append(formatDouble(v));
  return line + "\n";
}

void requireLater(Time previous, Time t, std::size_t count, const char* what) {
  if (count > 0 && t <= previous)
    throw std::invalid_argument(std::string("euroc writer: ") + what + " " + std::to_string(count) + " at " +
                                formatSeconds(t) + " s is not after the previous one at " + formatSeconds(previous) +
                                " s");
}

StagingRules eurocStagingRules(bool overwrite) {
  StagingRules rules;
  rules.may_replace = overwrite;
  rules.replace_hint = "use --force to replace it";
  rules.replaceable = eurocDatasetProblem;
  rules.refusal = "--force replaces only an earlier simulated dataset";
  return rules;
}

}  // namespace

std::string eurocDatasetProblem(const fs::path& dir) {
  std::error_code ec;
  if (fs::is_empty(dir, ec) && !ec) return "";
  if (!fs::is_regular_file(fs::symlink_status(dir / kScenarioFile, ec)) ||
      !fs::is_directory(fs::symlink_status(dir / "mav0", ec)))
    return "is not a simulated EuRoC dataset (no scenario.json and mav0/)";
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name != kScenarioFile && name != "mav0" && !isStagingLeftover(name))
      return "holds " + name + ", which drover sim does not write";
  }
  if (ec) return "cannot be listed: " + ec.message();
  return "";
}

void EurocDatasetWriter::checkOutput(const std::string& dir, bool overwrite) {
  StagedFolder::check(dir, eurocStagingRules(overwrite));
}

EurocDatasetWriter::EurocDatasetWriter(const std::string& dir, const SimDatasetDescription& description,
                                       bool overwrite)
    : description_(description) {
  const CameraIntrinsics& k = description.calibration.camera;
  if (description.sensors.camera_channels != 1)
    throw std::invalid_argument("euroc writer: EuRoC's cameras are mono8, got " +
                                std::to_string(description.sensors.camera_channels) + " channels");
  if (k.distortion != DistortionModel::kNone && k.distortion != DistortionModel::kRadialTangential)
    throw std::invalid_argument("euroc writer: only pinhole cameras with radial-tangential distortion");
  staged_ = std::make_unique<StagedFolder>(dir, eurocStagingRules(overwrite));
  mav0_ = staged_->dir() / "mav0";
  std::error_code ec;
  for (const char* sub : {"imu0", "cam0/data", "state_groundtruth_estimate0"}) {
    fs::create_directories(mav0_ / sub, ec);
    if (ec) fail((mav0_ / sub).string(), "", "cannot create folder: " + ec.message());
  }
  imu_csv_ =
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],"
      "a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  camera_csv_ = "#timestamp [ns],filename\n";
}

void EurocDatasetWriter::add(Measurement&& m) {
  if (finished_) throw std::logic_error("euroc writer: add() after finish()");
  if (const auto* s = std::get_if<ImuSample>(&m)) {
    requireLater(last_imu_, s->t, imu_count_, "IMU sample");
    if (!s->omega_imu.allFinite() || !s->acc_imu.allFinite())
      throw std::invalid_argument("euroc writer: IMU sample " + std::to_string(imu_count_) + " is not finite");
    std::string line = std::to_string(s->t);
    for (double v : {s->omega_imu.x(), s->omega_imu.y(), s->omega_imu.z(), s->acc_imu.x(), s->acc_imu.y(),
                     s->acc_imu.z()})
      line.append(1, ',').append(formatDouble(v));
    imu_csv_ += line + "\n";
    last_imu_ = s->t;
    ++imu_count_;
    return;
  }
  if (std::holds_alternative<LidarScan>(m))
    throw std::invalid_argument("euroc writer: EuRoC's layout has no lidar (simulate without it)");
  const CameraFrame& f = std::get<CameraFrame>(m);
  requireLater(last_frame_, f.t, frame_count_, "camera frame");
  const CameraIntrinsics& k = description_.calibration.camera;
  const Image& img = f.image;
  if (img.width != k.width || img.height != k.height || img.channels != 1 ||
      img.data.size() != static_cast<std::size_t>(img.width) * img.height)
    throw std::invalid_argument("euroc writer: camera frame " + std::to_string(frame_count_) + " is not a " +
                                std::to_string(k.width) + "x" + std::to_string(k.height) + " mono8 image");
  const std::string name = std::to_string(f.t) + ".png";
  const fs::path path = mav0_ / "cam0" / "data" / name;
  const cv::Mat mat(img.height, img.width, CV_8UC1, const_cast<std::uint8_t*>(img.data.data()));
  if (!cv::imwrite(path.string(), mat, {cv::IMWRITE_PNG_COMPRESSION, 1}))
    fail(path.string(), "", "cannot write PNG (disk full?)");
  camera_csv_ += std::to_string(f.t) + "," + name + "\n";
  last_frame_ = f.t;
  ++frame_count_;
}

void EurocDatasetWriter::finish(const std::vector<EurocTruthState>& truth) {
  if (finished_) throw std::logic_error("euroc writer: finish() called twice");
  std::string csv =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
      "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], "
      "b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  for (std::size_t i = 0; i < truth.size(); ++i) {
    requireLater(i > 0 ? truth[i - 1].t : 0, truth[i].t, i, "ground-truth state");
    csv += truthLine(truth[i]);
  }
  writeFileAtomically((mav0_ / "state_groundtruth_estimate0" / "data.csv").string(), csv);
  writeFileAtomically((mav0_ / "imu0" / "data.csv").string(), imu_csv_);
  writeFileAtomically((mav0_ / "imu0" / "sensor.yaml").string(), imuYaml(description_.sensors));
  writeFileAtomically((mav0_ / "cam0" / "data.csv").string(), camera_csv_);
  writeFileAtomically((mav0_ / "cam0" / "sensor.yaml").string(), cameraYaml(description_));
  writeFileAtomically((staged_->dir() / kScenarioFile).string(),
                      scenarioJson(description_.scenario, description_.sensors));
  staged_->publish();
  finished_ = true;
}

}  // namespace drover::io
