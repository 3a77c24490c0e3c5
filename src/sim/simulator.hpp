#pragma once
// Runs the sensor models over a scenario and hands every measurement, in global time order, to a sink (the
// dataset writer in io/, or a test). Sensor stamps include the configured time offsets: a sensor's stamp is
// t_true - offset, so that t_imu = t_sensor + offset as Calibration defines it.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sim/camera_model.hpp"
#include "sim/imu_model.hpp"
#include "sim/lidar_model.hpp"
#include "sim/scenario.hpp"
#include "sim/sensor_faults.hpp"
#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "types/trajectory.hpp"

namespace drover::io {
struct SimDatasetDescription;  // io/sim_dataset.hpp (plain data; the sim library calls no io function)
struct SimGroundTruthState;
}

namespace drover::sim {

// Version of the generator, written into scenario.json; bump when the same seed would give different data.
constexpr const char* kGeneratorVersion = "drover-sim 2";

struct SimulatorConfig {
  LidarModelConfig lidar = LidarModelConfig::forModel("vlp16");
  CameraModelConfig camera;
  ImuModelConfig imu;
  bool enable_lidar = true, enable_camera = true, enable_imu = true;
  // Extrinsics T_imu_sensor. defaults() sets those of a small ground robot: lidar 0.30 m above and 0.05 m ahead
  // of the IMU, axes as the body's (x forward, y left, z up); camera 0.20 m ahead and 0.10 m up looking forward
  // (camera z = body x, camera x = -body y, camera y = -body z) with a deliberate ~1 deg misalignment.
  // A default-constructed config keeps identities.
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  // The IMU's axes in the trajectory's body frame (x forward, y left, z up), at its origin: identity on every ground
  // rig (the IMU is the body). The IMU's samples, the calibration and the ground truth are all of the IMU's frame.
  Eigen::Matrix3d R_body_imu = Eigen::Matrix3d::Identity();
  // t_imu = t_sensor + offset [ns] (as Calibration): a sensor's stamp is t_true - offset. The IMU is the clock.
  Time lidar_time_offset = 0;    // [ns]
  Time camera_time_offset = 0;   // [ns]; defaults() sets 5 ms (camera stamps 5 ms early)
  double ground_truth_rate_hz = 200.0;  // [Hz], >= 100
  // Injected sensor faults (sensor_faults.hpp), windows in true time; the ground truth is complete regardless.
  std::vector<SensorFault> faults;
  // The above with the robot's default extrinsics, offsets and camera intrinsics filled in.
  static SimulatorConfig defaults();
  // EuRoC's MAV rig (Burri et al., IJRR 2016; the dataset's own sensor.yaml files): no lidar; cam0, an MT9V034
  // global shutter, 752x480 mono at 20 Hz hardware-synchronised with the IMU (no time offset), its intrinsics,
  // distortion and T_BS; the ADIS16448 IMU at 200 Hz with the noise densities and random walks of imu0/sensor.yaml
  // and turn-on biases of the size V1_01's ground truth estimates; the IMU's axes as EuRoC's (x up, y right,
  // z forward when level). For the mav-room scenario and `drover sim --format euroc`.
  static SimulatorConfig eurocRig();
  std::string validate() const;  // empty when valid, else names the bad value
};

class Simulator {
 public:
  // Per-sensor seeds are hashKeys(seed, Stream::kImu | kLidar | kCamera). Throws std::invalid_argument when
  // config.validate() fails or the scenario has no trajectory. Keeps a reference to `scenario`.
  Simulator(const Scenario& scenario, const SimulatorConfig& config, std::uint64_t seed);
  Calibration calibration() const;
  Trajectory groundTruth() const;  // T_world_imu at ground_truth_rate_hz
  // The same samples with the exact twist (velocity and angular rate in the IMU frame), for nav_msgs/Odometry.
  std::vector<io::SimGroundTruthState> groundTruthStates() const;
  // The IMU's true biases at its stamps (before any fault's gap), for a ground truth that carries them (EuRoC's).
  std::vector<ImuBiasSample> imuBiases() const;
  // Generates everything in time order of the stamps (ties: IMU, then lidar, then camera). IMU samples come from
  // simulateImu over the whole trajectory; sweep k starts at start + k / lidar rate while its end is inside the
  // trajectory; frame k is exposed (mid-exposure) at start + exposure / 2 + k / camera rate while the exposure
  // ends inside it. Work is done in chunks of `chunk` of stamp time: the chunk's sweeps and frames are computed
  // in parallel (TBB, nested in the models' own row/column parallelism), then handed over in order, so memory
  // holds one chunk of images. The sink is called from the calling thread only.
  void run(const std::function<void(Measurement&&)>& sink, Time chunk = kNanosPerSecond) const;
  // Counts run() will produce (for progress and tests).
  struct Counts {
    std::size_t imu = 0, lidar = 0, camera = 0;
  };
  Counts expectedCounts() const;  // after the faults' drops
  // What the dataset writer needs besides the measurements: calibration, sensor settings, scenario labels.
  io::SimDatasetDescription datasetDescription() const;

 private:
  std::vector<Time> sweepStarts() const;  // true start times [ns]
  std::vector<Time> frameTimes() const;   // true mid-exposure times [ns]
  bool sweepDropped(Time t0) const;        // a lidar-dropout overlaps the sweep starting (true time) at t0
  Eigen::Isometry3d bodyFrom(const Eigen::Isometry3d& T_imu_sensor) const;  // T_body_sensor

  const Scenario& scenario_;
  SimulatorConfig config_;
  std::uint64_t seed_;
};

}  // namespace drover::sim
