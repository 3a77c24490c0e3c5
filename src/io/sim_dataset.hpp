#pragma once
// Drover's simulated-dataset folder (`drover sim` writes it, `--format sim` reads it). Version 1 layout:
//
//   DIR/calibration.yaml        extrinsics, intrinsics, time offsets and sensor settings (below); it is also a valid
//                               platform config, so its `calibration:` section can be passed with --config
//   DIR/imu.csv                 '#' header, then `t_ns,wx,wy,wz,ax,ay,az[,qw,qx,qy,qz]`: angular rate [rad/s] and
//                               specific force [m/s^2] in the IMU frame (+ q_world_imu when the unit reports it;
//                               every line has 7 or every line has 11 fields). Doubles are printed as the shortest
//                               text that reads back bit-exactly (std::to_chars), so imu.csv round-trips exactly.
//   DIR/lidar/timestamps.csv    '#' header, then `index,t_start_ns,t_end_ns`, index = 0, 1, 2, ...
//   DIR/lidar/NNNNNN.bin        (6-digit index) little-endian records of 24 bytes, one per point:
//                                 float32 x, y, z [m] (lidar frame, at the point's own firing time),
//                                 float32 intensity (0..255, Velodyne-like),
//                                 uint32 time offset [ns] from t_start (<= t_end - t_start),
//                                 uint16 ring (0 = lowest beam, < lidar rings), uint16 reserved (0)
//   DIR/camera/timestamps.csv   '#' header, then `index,t_ns` (mid-exposure stamp)
//   DIR/camera/NNNNNN.png       8-bit mono or BGR, camera.width x camera.height
//   DIR/groundtruth.txt         TUM `t x y z qx qy qz qw` [s, m], T_world_imu at ground_truth.rate_hz (>= 100 Hz)
//   DIR/scenario.json           {format_version, generator, scenario, seed, duration_s, path_length_m, closes_loop,
//                                lidar_model, sensors {imu, lidar, camera: bool},
//                                segments [{condition, start_ns, end_ns}],
//                                faults [{kind, start_ns, end_ns}] (optional: injected sensor faults)}
// All stamps are int64 ns on the IMU clock's epoch as each sensor reports them: a sensor stamp is
// t_true - offset, i.e. t_imu = t_sensor + offset with the offsets of calibration.yaml. A disabled sensor keeps
// its folder with a header-only timestamps.csv (imu.csv likewise), so the layout never changes.
//
// calibration.yaml:
//   calibration:
//     T_imu_lidar, T_imu_cam: 16 numbers, row-major 4x4 T_imu_sensor [m]
//     lidar_time_offset, camera_time_offset: [s] (9 decimals, exact to the ns)
//     camera: {width, height [px], fx, fy, cx, cy [px], distortion_model: radial-tangential | none,
//              distortion_coeffs: [k1, k2, p1, p2(, k3)]}
//   sensors:
//     lidar: {model: vlp16|vlp32|hdl64, rings, columns, rate_hz [Hz]}
//     camera: {rate_hz [Hz], channels: 1|3, exposure_s [s]}
//     imu: {rate_hz [Hz], gyro_noise_density [rad/s/sqrt(Hz)], accel_noise_density [m/s^2/sqrt(Hz)],
//           gyro_bias_random_walk [rad/s^2/sqrt(Hz)], accel_bias_random_walk [m/s^3/sqrt(Hz)]}
//     ground_truth: {rate_hz [Hz], body_frame: imu}
//
// The writer builds everything in DIR.partial/ and renames it to DIR only when complete, so an interrupted run
// never leaves a folder that looks like a dataset. The reader checks every file and record and throws IoError
// naming them (missing file or key, .bin size not a multiple of 24, unparsable values); as from real sensors, a
// lidar point with a non-finite value is dropped (LidarScan::dropped_nonfinite) and an IMU row, scan or image
// whose stamp does not advance is dropped with a warning in Reader::drops().
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "io/dataset.hpp"
#include "io/output_paths.hpp"
#include "io/reader.hpp"
#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "types/trajectory.hpp"

namespace drover::io {

constexpr int kSimFormatVersion = 1;
constexpr std::size_t kSimPointBytes = 24;  // bytes per lidar point record in NNNNNN.bin

// Sensor settings beyond the Calibration (the `sensors:` section of calibration.yaml).
struct SimSensorInfo {
  std::string lidar_model = "vlp16";
  int lidar_rings = 16;
  int lidar_columns = 1800;
  double lidar_rate_hz = 10.0;           // [Hz]
  double camera_rate_hz = 15.0;          // [Hz]
  int camera_channels = 1;               // 1 = mono8, 3 = bgr8
  double camera_exposure_s = 0.01;       // [s]
  int camera_pixel_samples = 1;          // rays per pixel side (sim::CameraModelConfig::pixel_samples)
  bool camera_texture_filter = false;    // textures averaged over each ray's footprint (CameraModelConfig)
  int camera_edge_pixel_samples = 0;     // rays per pixel side where a pixel's rays disagree; 0 = off
  double imu_rate_hz = 200.0;            // [Hz]
  double gyro_noise_density = 0;         // [rad/s/sqrt(Hz)]
  double accel_noise_density = 0;        // [m/s^2/sqrt(Hz)]
  double gyro_bias_random_walk = 0;      // [rad/s^2/sqrt(Hz)]
  double accel_bias_random_walk = 0;     // [m/s^3/sqrt(Hz)]
  double ground_truth_rate_hz = 200.0;   // [Hz]
};

struct SimSegmentInfo {
  std::string condition;  // "uphill", "white-walls", ...
  Time start = 0, end = 0;  // [ns]
};

// scenario.json.
struct SimScenarioInfo {
  std::string name;
  std::uint64_t seed = 0;
  double duration_s = 0;       // [s] of trajectory
  double path_length_m = 0;    // [m]
  bool closes_loop = false;
  std::string generator = "drover sim";  // generator name and version
  bool has_imu = true, has_lidar = true, has_camera = true;
  std::vector<SimSegmentInfo> segments;
  std::vector<SimSegmentInfo> faults;  // injected sensor faults: kind ("camera-blackout", ...) and window [ns]
};

// One ground-truth sample of the simulated body (= IMU) with its exact twist, on the simulation's clock (the bag's
// nav_msgs/Odometry; the folder's groundtruth.txt keeps the pose only).
struct SimGroundTruthState {
  Time t = 0;  // [ns]
  Eigen::Isometry3d T_world_imu = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_imu = Eigen::Vector3d::Zero();      // [m/s] velocity in the IMU frame
  Eigen::Vector3d omega_imu = Eigen::Vector3d::Zero();  // [rad/s] angular rate in the IMU frame
};

struct SimDatasetDescription {
  Calibration calibration;
  SimSensorInfo sensors;
  SimScenarioInfo scenario;
};

// "" when DIR (an existing folder) is empty or holds a complete simulated dataset and nothing else, so replacing it
// loses nothing but that dataset; else why not ("holds notes.txt, which drover sim does not write ...").
std::string simDatasetProblem(const std::filesystem::path& dir);

struct SimWriterOptions {
  // Replace an existing DIR, which must then be a dataset (simDatasetProblem) and not a folder that is never
  // replaced (io/output_paths.hpp); else the constructor throws IoError(DIR, "--out", why).
  bool overwrite = false;
  int png_compression = 1;      // cv::IMWRITE_PNG_COMPRESSION, 0..9 (1: fast; images are large and many)
  std::size_t max_queued_images = 16;  // images waiting for the background PNG encoder
};

// Counts of what a writer has written.
struct SimWriterCounts {
  std::size_t imu = 0, lidar = 0, camera = 0, lidar_points = 0;
};

// Writes a dataset measurement by measurement (each stream must come in strictly increasing time; other input
// throws std::invalid_argument). PNGs are encoded on a background thread while the caller goes on.
// The constructor removes a leftover DIR.partial only when an interrupted writer left it (its marker file, or a
// complete dataset). finish() writes the ground truth and the index files and swaps DIR.partial in as DIR (an
// earlier DIR stays whole until then); a writer destroyed without finish() removes DIR.partial.
class SimDatasetWriter {
 public:
  SimDatasetWriter(const std::string& dir, const SimDatasetDescription& description,
                   const SimWriterOptions& options = {});
  ~SimDatasetWriter();
  SimDatasetWriter(const SimDatasetWriter&) = delete;
  SimDatasetWriter& operator=(const SimDatasetWriter&) = delete;

  void add(Measurement&& m);
  // Why DIR may not be written with these options (checked by the constructor too); throws IoError.
  static void checkOutput(const std::string& dir, const SimWriterOptions& options);
  // ground_truth: T_world_imu, strictly increasing in time.
  void finish(const Trajectory& ground_truth);
  const SimWriterCounts& counts() const { return counts_; }
  const std::filesystem::path& partialDir() const { return partial_; }

 private:
  struct PendingImage {
    std::filesystem::path path;
    Image image;
  };
  void addImu(const ImuSample& s);
  void addScan(const LidarScan& scan);
  void addFrame(CameraFrame&& frame);
  void encoderLoop();
  void stopEncoder();
  void rethrowEncoderError();

  std::unique_ptr<StagedFolder> staged_;
  std::filesystem::path dir_, partial_;
  SimDatasetDescription description_;
  SimWriterOptions options_;
  SimWriterCounts counts_;
  std::string imu_csv_, lidar_csv_, camera_csv_;
  Time last_imu_ = 0, last_lidar_ = 0, last_camera_ = 0;
  bool imu_has_orientation_ = false;
  bool finished_ = false;
  // Background PNG encoder.
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<PendingImage> queue_;
  bool stop_ = false;
  std::string encoder_error_;
  std::thread encoder_;
};

// The `sim:` section of a platform config (config/farm_sim.yaml): sensor settings for `drover sim`. Keys left out
// keep the simulator's defaults; an unknown key or a bad value throws IoError naming file, line and key.
// Limits of what `drover sim` generates, shared by its options and the `sim:` keys (io/user_values.hpp checks
// both). The simulator holds the whole IMU stream, the schedule, the ground truth and the path (a sample every
// 0.1 s) in memory before the first file is written, so memory grows with duration x rate: an hour at these
// maxima is about 1 GB. Longer than its natural length a closed course is driven again lap after lap.
constexpr double kMaxSimDurationS = 3600;      // [s]
constexpr double kMaxSimImuRateHz = 1000;      // [Hz]
constexpr double kMaxSimLidarRateHz = 50;      // [Hz]; spinning lidars turn at 5..20 Hz
constexpr double kMaxSimCameraRateHz = 60;     // [Hz]; the 10 ms exposure also needs rate < 100 Hz
constexpr double kMinSimGroundTruthRateHz = 100;   // [Hz]
constexpr double kMaxSimGroundTruthRateHz = 1000;  // [Hz]
constexpr double kMaxSimTimeOffsetS = 1;       // [s] |lidar_time_offset|, |camera_time_offset|

struct SimConfigSettings {
  // robot: the farm robot's rig (sim::SimulatorConfig::defaults()); euroc: EuRoC's MAV (camera + IMU, no lidar;
  // sim::SimulatorConfig::eurocRig()). The keys below change either.
  std::optional<std::string> rig;
  std::optional<std::string> lidar_model;        // vlp16 | vlp32 | hdl64
  std::optional<double> lidar_rate_hz;           // [Hz]
  std::optional<int> lidar_columns;              // firings per revolution
  std::optional<double> camera_rate_hz;          // [Hz]
  std::optional<bool> camera_color;              // bgr8 instead of mono8
  std::optional<int> camera_pixel_samples;       // rays per pixel side, 1 ... 4 (sim::CameraModelConfig)
  std::optional<bool> camera_texture_filter;     // textures averaged over each ray's footprint
  std::optional<int> camera_edge_pixel_samples;  // rays per pixel side where a pixel's rays disagree: 0 (off) ... 4
  std::optional<double> imu_rate_hz;             // [Hz]
  std::optional<double> ground_truth_rate_hz;    // [Hz], >= 100
  std::optional<double> lidar_time_offset_s;     // [s], t_imu = t_lidar + offset
  std::optional<double> camera_time_offset_s;    // [s], t_imu = t_camera + offset
  std::optional<bool> noise;                     // false: exact sensors (no noise, biases, dropouts)
};
SimConfigSettings loadSimConfigSettings(const std::string& yaml_path);

// calibration.yaml, scenario.json alone (the reader uses them; tools may too). Throw IoError naming the key.
SimDatasetDescription readSimDescription(const std::string& dir);

// The `--format sim` reader: IMU, lidar scans (has_time, has_ring) and camera frames merged in time order
// (ties: IMU, lidar, camera); ground truth from groundtruth.txt with body_frame "imu". Scans and images are loaded
// lazily. options.load_imu / load_lidar / load_images are honoured.
std::unique_ptr<Reader> openSimDataset(const std::string& dir, const DatasetOptions& options);

// File name of record `index` in lidar/ or camera/: six digits and the extension ("000042.bin").
std::string simFileName(std::size_t index, const char* extension);

}  // namespace drover::io
