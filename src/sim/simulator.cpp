// The simulator: runs the IMU, lidar and camera models over a scenario and merges their output in time order.
#include "sim/simulator.hpp"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "io/sim_dataset.hpp"
#include "sim/camera_stream.hpp"
#include "sim/random.hpp"

namespace drover::sim {
namespace {

// Time of event k of a periodic stream: start + k / rate, rounded to the ns (no accumulated drift).
Time periodic(Time start, std::size_t k, double rate_hz) {
  return start + static_cast<Time>(std::llround(static_cast<double>(k) * 1e9 / rate_hz));
}

bool isRigid(const Eigen::Isometry3d& T) {
  const Eigen::Matrix3d R = T.linear();
  return T.matrix().allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-9 &&
         R.determinant() > 0;
}

// One scheduled measurement: its stamp, its sensor (0 = IMU, 1 = lidar, 2 = camera: the tie order) and its index
// in that sensor's stream.
struct Slot {
  Time stamp = 0;
  int sensor = 0;
  std::size_t index = 0;
  bool operator<(const Slot& o) const {
    if (stamp != o.stamp) return stamp < o.stamp;
    if (sensor != o.sensor) return sensor < o.sensor;
    return index < o.index;
  }
};

// The whole schedule by stamp (cheap: times only); sensor stamps are true times minus the offsets.
std::vector<Slot> buildSchedule(const std::vector<ImuSample>& imu, const std::vector<Time>& sweeps,
                                const std::vector<Time>& frames, Time lidar_offset, Time camera_offset) {
  std::vector<Slot> schedule;
  schedule.reserve(imu.size() + sweeps.size() + frames.size());
  for (std::size_t i = 0; i < imu.size(); ++i) schedule.push_back({imu[i].t, 0, i});
  for (std::size_t i = 0; i < sweeps.size(); ++i) schedule.push_back({sweeps[i] - lidar_offset, 1, i});
  for (std::size_t i = 0; i < frames.size(); ++i) schedule.push_back({frames[i] - camera_offset, 2, i});
  std::sort(schedule.begin(), schedule.end());
  return schedule;
}

}  // namespace

SimulatorConfig SimulatorConfig::defaults() {
  SimulatorConfig c;
  c.camera.intrinsics = CameraModelConfig::defaultIntrinsics();
  c.T_imu_lidar = Eigen::Isometry3d::Identity();
  c.T_imu_lidar.translation() = Eigen::Vector3d(0.05, 0.0, 0.30);  // [m]
  // Columns: the camera's x, y, z axes in the body frame (x right = -body y, y down = -body z, z forward = body x).
  Eigen::Matrix3d R_imu_camnominal;
  R_imu_camnominal << 0, 0, 1,  //
      -1, 0, 0,                 //
      0, -1, 0;
  // A deliberate ~1 deg mounting error about a generic axis, so the extrinsics are not axis-aligned.
  const Eigen::AngleAxisd misalignment(1.0 * std::numbers::pi / 180.0, Eigen::Vector3d(0.3, -0.5, 0.8).normalized());
  c.T_imu_cam = Eigen::Isometry3d::Identity();
  c.T_imu_cam.linear() = R_imu_camnominal * misalignment.toRotationMatrix();
  c.T_imu_cam.translation() = Eigen::Vector3d(0.20, 0.0, 0.10);  // [m]
  c.lidar_time_offset = 0;
  c.camera_time_offset = 5'000'000;  // [ns]: camera stamps are 5 ms early (t_imu = t_cam + 5 ms)
  return c;
}

SimulatorConfig SimulatorConfig::eurocRig() {
  SimulatorConfig c;
  c.enable_lidar = false;
  CameraIntrinsics& k = c.camera.intrinsics;  // mav0/cam0/sensor.yaml
  k.width = 752;
  k.height = 480;
  k.fx = 458.654;
  k.fy = 457.296;
  k.cx = 367.215;
  k.cy = 248.375;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  c.camera.rate_hz = 20.0;
  c.imu.rate_hz = 200.0;  // mav0/imu0/sensor.yaml
  c.imu.gyro_noise_density = 1.6968e-04;
  c.imu.gyro_bias_random_walk = 1.9393e-05;
  c.imu.accel_noise_density = 2.0e-3;
  c.imu.accel_bias_random_walk = 3.0e-3;
  c.imu.orientation = false;  // a bare IMU: no orientation estimate
  // The shared V1_01 snippet's IMU at rest reads (-0.002, 0.019, 0.078) rad/s; accelerometer biases of ~0.1 m/s^2.
  c.imu.initial_gyro_bias = Eigen::Vector3d(-0.002, 0.019, 0.078);
  c.imu.initial_accel_bias = Eigen::Vector3d(-0.02, 0.12, 0.075);
  // EuRoC's IMU axes in the body frame: x up (body z), y right (-body y), z forward (body x).
  c.R_body_imu << 0, 0, 1,  //
      0, -1, 0,             //
      1, 0, 0;
  Eigen::Matrix4d T_BS;  // mav0/cam0/sensor.yaml: cam0 -> IMU (EuRoC's body frame B is the IMU's)
  T_BS << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,          //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,      //
      0.0, 0.0, 0.0, 1.0;
  // Calibrated, so orthonormal only to ~1e-9: re-orthonormalised to pass as a rigid transform.
  const Eigen::Quaterniond q(Eigen::Matrix3d(T_BS.topLeftCorner<3, 3>()));
  c.T_imu_cam = Eigen::Isometry3d::Identity();
  c.T_imu_cam.linear() = q.normalized().toRotationMatrix();
  c.T_imu_cam.translation() = T_BS.topRightCorner<3, 1>();
  c.camera_time_offset = 0;
  return c;
}

std::string SimulatorConfig::validate() const {
  std::ostringstream e;
  if (!enable_imu && !enable_lidar && !enable_camera) return "at least one sensor must be enabled";
  if (enable_lidar)
    if (std::string s = lidar.validate(); !s.empty()) return "lidar: " + s;
  if (enable_camera)
    if (std::string s = camera.validate(); !s.empty()) return "camera: " + s;
  if (enable_imu)
    if (std::string s = imu.validate(); !s.empty()) return "imu: " + s;
  if (!(ground_truth_rate_hz >= 100.0) || !std::isfinite(ground_truth_rate_hz)) {
    e << "ground_truth_rate_hz must be >= 100, got " << ground_truth_rate_hz;
  } else if (!isRigid(T_imu_lidar)) {
    e << "T_imu_lidar is not a rigid transform";
  } else if (!isRigid(T_imu_cam)) {
    e << "T_imu_cam is not a rigid transform";
  } else if (Eigen::Isometry3d R = Eigen::Isometry3d(R_body_imu); !isRigid(R)) {
    e << "R_body_imu is not a rotation";
  } else if (std::string f = validateFaults(faults); !f.empty()) {
    e << f;
  } else if (std::abs(lidar_time_offset) > kNanosPerSecond || std::abs(camera_time_offset) > kNanosPerSecond) {
    e << "time offsets must be within 1 s, got lidar " << lidar_time_offset << " ns, camera " << camera_time_offset
      << " ns";
  }
  return e.str();
}

Simulator::Simulator(const Scenario& scenario, const SimulatorConfig& config, std::uint64_t seed)
    : scenario_(scenario), config_(config), seed_(seed) {
  if (std::string e = config.validate(); !e.empty()) throw std::invalid_argument("SimulatorConfig: " + e);
  if (!scenario.trajectory) throw std::invalid_argument("scenario '" + scenario.name + "' has no trajectory");
}

Eigen::Isometry3d Simulator::bodyFrom(const Eigen::Isometry3d& T_imu_sensor) const {
  if (config_.R_body_imu == Eigen::Matrix3d::Identity()) return T_imu_sensor;  // the same bits on ground rigs
  return Eigen::Isometry3d(config_.R_body_imu) * T_imu_sensor;
}

std::vector<ImuBiasSample> Simulator::imuBiases() const {
  std::vector<ImuBiasSample> biases;
  if (config_.enable_imu)
    simulateImu(*scenario_.trajectory, config_.imu, hashKeys(seed_, static_cast<std::uint64_t>(Stream::kImu)),
                config_.R_body_imu, &biases);
  return biases;
}

Calibration Simulator::calibration() const {
  Calibration c;
  c.T_imu_lidar = config_.T_imu_lidar;
  c.T_imu_cam = config_.T_imu_cam;
  c.camera = config_.camera.intrinsics;
  c.lidar_time_offset = config_.lidar_time_offset;
  c.camera_time_offset = config_.camera_time_offset;
  return c;
}

Trajectory Simulator::groundTruth() const {
  Trajectory truth = scenario_.trajectory->sample(config_.ground_truth_rate_hz);
  if (config_.R_body_imu != Eigen::Matrix3d::Identity())
    for (StampedPose& p : truth) p.T_world_body.linear() = p.T_world_body.linear() * config_.R_body_imu;
  return truth;
}

std::vector<io::SimGroundTruthState> Simulator::groundTruthStates() const {
  std::vector<io::SimGroundTruthState> out;
  const bool body_is_imu = config_.R_body_imu == Eigen::Matrix3d::Identity();
  for (const StampedPose& p : groundTruth()) {
    const BodyState b = scenario_.trajectory->at(p.t);
    Eigen::Vector3d v = b.T_world_body.linear().transpose() * b.v_world, w = b.omega_body;
    if (!body_is_imu) v = config_.R_body_imu.transpose() * v, w = config_.R_body_imu.transpose() * w;
    out.push_back({p.t, p.T_world_body, v, w});
  }
  return out;
}

std::vector<Time> Simulator::sweepStarts() const {
  std::vector<Time> t;
  if (!config_.enable_lidar) return t;
  const Time start = scenario_.trajectory->startTime(), end = scenario_.trajectory->endTime();
  const Time period = static_cast<Time>(std::llround(1e9 / config_.lidar.rate_hz));
  for (std::size_t k = 0;; ++k) {
    const Time t0 = periodic(start, k, config_.lidar.rate_hz);
    if (t0 + period > end) break;
    t.push_back(t0);
  }
  return t;
}

std::vector<Time> Simulator::frameTimes() const {
  std::vector<Time> t;
  if (!config_.enable_camera) return t;
  const Time start = scenario_.trajectory->startTime(), end = scenario_.trajectory->endTime();
  const Time half_exposure = fromSeconds(config_.camera.exposure_s / 2);
  for (std::size_t k = 0;; ++k) {
    const Time mid = periodic(start + half_exposure, k, config_.camera.rate_hz);
    if (mid + half_exposure > end) break;
    t.push_back(mid);
  }
  return t;
}

bool Simulator::sweepDropped(Time t0) const {
  const Time period = static_cast<Time>(std::llround(1e9 / config_.lidar.rate_hz));
  return faulted(config_.faults, FaultKind::kLidarDropout, t0, t0 + period);
}

Simulator::Counts Simulator::expectedCounts() const {
  Counts c;
  if (config_.enable_imu) {
    const Time start = scenario_.trajectory->startTime(), end = scenario_.trajectory->endTime();
    for (std::size_t k = 0;; ++k) {
      const Time t = periodic(start, k, config_.imu.rate_hz);
      if (t > end) break;
      if (!faulted(config_.faults, FaultKind::kImuGap, t)) ++c.imu;
    }
  }
  for (Time t0 : sweepStarts()) c.lidar += sweepDropped(t0) ? 0 : 1;
  c.camera = frameTimes().size();
  return c;
}

void Simulator::run(const std::function<void(Measurement&&)>& sink, Time chunk) const {
  if (chunk <= 0) throw std::invalid_argument("Simulator::run: chunk must be positive, got " + std::to_string(chunk));
  const SplineTrajectory& trajectory = *scenario_.trajectory;
  const std::uint64_t imu_seed = hashKeys(seed_, static_cast<std::uint64_t>(Stream::kImu));
  const std::uint64_t lidar_seed = hashKeys(seed_, static_cast<std::uint64_t>(Stream::kLidar));
  const std::uint64_t camera_seed = hashKeys(seed_, static_cast<std::uint64_t>(Stream::kCamera));

  std::vector<ImuSample> imu;
  if (config_.enable_imu) imu = simulateImu(trajectory, config_.imu, imu_seed, config_.R_body_imu);
  const Eigen::Isometry3d T_body_lidar = bodyFrom(config_.T_imu_lidar), T_body_cam = bodyFrom(config_.T_imu_cam);
  const std::vector<Time> sweeps = sweepStarts();
  const std::vector<Time> frames = frameTimes();
  // The camera runs in frame order (its auto exposure meters each frame for the next); sweeps run in parallel.
  std::optional<CameraStream> camera;
  if (config_.enable_camera) camera.emplace(config_.camera);

  std::vector<Slot> schedule =
      buildSchedule(imu, sweeps, frames, config_.lidar_time_offset, config_.camera_time_offset);
  // Faults drop slots, never renumber them: every sample outside a fault keeps its index and so its noise.
  std::erase_if(schedule, [&](const Slot& s) {
    if (s.sensor == 0) return faulted(config_.faults, FaultKind::kImuGap, imu[s.index].t);
    if (s.sensor == 1) return sweepDropped(sweeps[s.index]);
    return false;
  });
  const auto sweep = [&](const Slot& s) -> Measurement {
    LidarScan scan = simulateSweep(scenario_.world, trajectory, T_body_lidar, sweeps[s.index], config_.lidar,
                                   lidar_seed, s.index);
    const Time duration = scan.t_end - scan.t;
    scan.t = s.stamp;
    scan.t_end = s.stamp + duration;
    return scan;
  };
  const auto frame = [&](const Slot& s) -> Measurement {
    const Time t = frames[s.index];
    const FrameCondition condition{faulted(config_.faults, FaultKind::kCameraBlackout, t),
                                   faulted(config_.faults, FaultKind::kTextureless, t)};
    CameraFrame f = camera->next(scenario_.world, trajectory, T_body_cam, scenario_.illumination, t,
                                 camera_seed, s.index, condition);
    f.t = s.stamp;
    return f;
  };
  std::size_t begin = 0;
  while (begin < schedule.size()) {
    const Time chunk_end = schedule[begin].stamp + chunk;
    std::size_t end = begin;
    while (end < schedule.size() && schedule[end].stamp < chunk_end) ++end;
    // Sweeps of this chunk in parallel, alongside its frames in order; each into its slot.
    std::vector<std::size_t> lidar_slots, camera_slots;
    for (std::size_t i = begin; i < end; ++i) {
      if (schedule[i].sensor == 1) lidar_slots.push_back(i);
      if (schedule[i].sensor == 2) camera_slots.push_back(i);
    }
    std::vector<std::optional<Measurement>> results(end - begin);
    tbb::parallel_invoke(
        [&] {
          tbb::parallel_for(std::size_t{0}, lidar_slots.size(), [&](std::size_t h) {
            results[lidar_slots[h] - begin] = sweep(schedule[lidar_slots[h]]);
          });
        },
        [&] {
          for (std::size_t i : camera_slots) results[i - begin] = frame(schedule[i]);
        });
    for (std::size_t i = begin; i < end; ++i) {
      if (schedule[i].sensor == 0)
        sink(Measurement(imu[schedule[i].index]));
      else
        sink(std::move(*results[i - begin]));
    }
    begin = end;
  }
}

io::SimDatasetDescription Simulator::datasetDescription() const {
  io::SimDatasetDescription d;
  d.calibration = calibration();
  io::SimSensorInfo& s = d.sensors;
  s.lidar_model = config_.lidar.model;
  s.lidar_rings = static_cast<int>(config_.lidar.elevations.size());
  s.lidar_columns = config_.lidar.columns;
  s.lidar_rate_hz = config_.lidar.rate_hz;
  s.camera_rate_hz = config_.camera.rate_hz;
  s.camera_channels = config_.camera.color ? 3 : 1;
  s.camera_exposure_s = config_.camera.exposure_s;
  s.camera_pixel_samples = config_.camera.pixel_samples;
  s.camera_texture_filter = config_.camera.texture_filter;
  s.camera_edge_pixel_samples = config_.camera.edge_pixel_samples;
  const ImuModelConfig& imu = config_.imu;
  s.imu_rate_hz = imu.rate_hz;
  // The densities of the data as generated: zero when the model's noise is off.
  s.gyro_noise_density = imu.noise ? imu.gyro_noise_density : 0.0;
  s.accel_noise_density = imu.noise ? imu.accel_noise_density : 0.0;
  s.gyro_bias_random_walk = imu.noise ? imu.gyro_bias_random_walk : 0.0;
  s.accel_bias_random_walk = imu.noise ? imu.accel_bias_random_walk : 0.0;
  s.ground_truth_rate_hz = config_.ground_truth_rate_hz;
  io::SimScenarioInfo& sc = d.scenario;
  const SplineTrajectory& trajectory = *scenario_.trajectory;
  sc.name = scenario_.name;
  sc.seed = seed_;
  sc.duration_s = toSeconds(trajectory.endTime() - trajectory.startTime());
  sc.path_length_m = trajectory.pathLength();
  sc.closes_loop = scenario_.closes_loop;
  sc.generator = kGeneratorVersion;
  sc.has_imu = config_.enable_imu;
  sc.has_lidar = config_.enable_lidar;
  sc.has_camera = config_.enable_camera;
  for (const Segment& seg : scenario_.segments)
    sc.segments.push_back({conditionName(seg.condition), seg.start, seg.end});
  for (const SensorFault& f : config_.faults) sc.faults.push_back({faultName(f.kind), f.start, f.end});
  return d;
}

}  // namespace drover::sim
