#pragma once
// Static gravity / attitude initialisation from a window of IMU samples. At rest the accelerometer measures
// f = R_world_imu^T (0, 0, g) (plus bias and noise), so the mean specific force gives roll and pitch
// (R_world_imu = Rz(yaw) Ry(pitch) Rx(roll), Z-Y-X):
//   roll = atan2(f_y, f_z),  pitch = atan2(-f_x, sqrt(f_y^2 + f_z^2)),
// and the mean angular rate is the gyro bias. Yaw is unobservable from gravity: 0, unless the samples carry a
// 9-axis unit's own orientation, which is then used whole. The accelerometer bias is not separable from tilt at
// rest and is returned as zero.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "types/imu.hpp"

namespace drover::imu {

class StaticInitializer {
 public:
  struct Config {
    double window_s = 1.0;         // [s] the newest window_s of the samples given is used
    double min_coverage = 0.8;     // [-] the samples must span at least this fraction of window_s
    // Static when all of these hold. "std" is the root of the summed per-axis variances over the window.
    double max_gyro_std = 0.02;    // [rad/s]; white noise of 1.7e-4 rad/s/sqrt(Hz) at 200 Hz gives ~0.004
    double max_acc_std = 0.15;     // [m/s^2]; white noise of 2e-3 m/s^2/sqrt(Hz) at 200 Hz gives ~0.05
    double max_gyro_mean = 0.1;    // [rad/s] a larger mean rate is a turn, not a gyro bias
    double max_gravity_error = 0.5;  // [m/s^2] allowed | |mean acc| - gravity |
    double gravity = 9.81;         // [m/s^2]
    bool use_orientation = true;   // use the samples' q_world_imu (9-axis units) when every sample has one
    // Empty when valid: all values finite and > 0, min_coverage in (0, 1].
    std::string validate() const;
  };

  struct Result {
    bool ok = false;         // an attitude was computed (enough finite samples); false: only `reason` is meaningful
    bool is_static = false;  // the window passed the static tests; when false the attitude is still returned
    std::string reason;      // why not ok / not static; empty when static
    Eigen::Quaterniond q_world_imu = Eigen::Quaterniond::Identity();
    ImuBias bias;                      // gyro: mean rate when static, else zero; acc: zero
    double gravity_magnitude = 0;      // [m/s^2] norm of the mean specific force
    Eigen::Vector3d mean_specific_force = Eigen::Vector3d::Zero();  // [m/s^2] over the window, IMU frame
    Time window_end = 0;               // [ns] the newest finite sample of the window
    double gyro_std = 0, acc_std = 0;  // [rad/s], [m/s^2] the measured spreads
    double tilt_mismatch = 0;          // [rad] angle between the 9-axis "up" and the mean specific force (0 if
                                       // no orientation was used)
    bool used_orientation = false;     // q_world_imu came from the samples' 9-axis orientation
    std::size_t samples_used = 0;
  };

  // Throws std::invalid_argument when config.validate() fails.
  StaticInitializer();  // default Config
  explicit StaticInitializer(const Config& config);

  // Time-ordered samples; the newest config.window_s of them are used.
  Result initialize(const std::vector<ImuSample>& samples) const;

  const Config& config() const { return config_; }

 private:
  Config config_;
};

// Roll/pitch attitude (yaw 0) that maps the specific force f (IMU frame) onto +z of the world.
Eigen::Quaterniond attitudeFromGravity(const Eigen::Vector3d& f_imu);

}  // namespace drover::imu
