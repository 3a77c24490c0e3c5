#pragma once
// The platform config's IMU noise (odometry.imu) held against what the dataset says of its IMU. The estimators use
// the config's figures only; a dataset's own are read to catch a config written for another IMU. EuRoC's ADIS16448
// walks its accelerometer bias at 3e-3 m/s^3/sqrt(Hz); config/euroc.yaml without an imu section weighed it by the
// farm robot's 3e-4, and the VIS's error on the simulated EuRoC flight grew from 0.023 to 0.058 m.
#include <string>
#include <vector>

#include "imu/preintegration.hpp"
#include "io/euroc_reader.hpp"

namespace drover::io {

// Below this factor (either way) a difference is a margin or a rounding, not another IMU. Tuned configs go further
// on purpose (VINS-Mono's EuRoC config: white noise 40x the accelerometer's and 24x the gyroscope's, bias walks
// 75x and 10x below), so what is reported is a warning that says which figure the estimators use.
inline constexpr double kImuNoiseReportFactor = 5.0;

// One line per figure of `sensor` that `used` differs from by more than `factor` (either way), naming the config
// (`config_name`, e.g. "config/euroc.yaml" or "built-in default"), its key, the sensor file and its key, both
// values and the ratio. A figure the sensor file leaves out, or gives as 0, is not compared.
std::vector<std::string> imuNoiseDisagreements(const EurocImuNoise& sensor, const imu::PreintegrationConfig& used,
                                               const std::string& config_name,
                                               double factor = kImuNoiseReportFactor);

}  // namespace drover::io
