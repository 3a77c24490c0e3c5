#include "io/odometry/imu_noise_check.hpp"

#include <fmt/format.h>

#include <optional>

namespace drover::io {

std::vector<std::string> imuNoiseDisagreements(const EurocImuNoise& sensor, const imu::PreintegrationConfig& used,
                                               const std::string& config_name, double factor) {
  struct Figure {
    std::optional<double> sensor;
    const char* sensor_key;
    double used;
    const char* config_key;
    const char* unit;
  };
  const Figure figures[] = {
      {sensor.gyroscope_noise_density, "gyroscope_noise_density", used.gyro_noise_density, "gyro_noise_density",
       "rad/s/sqrt(Hz)"},
      {sensor.gyroscope_random_walk, "gyroscope_random_walk", used.gyro_bias_random_walk, "gyro_bias_random_walk",
       "rad/s^2/sqrt(Hz)"},
      {sensor.accelerometer_noise_density, "accelerometer_noise_density", used.acc_noise_density, "acc_noise_density",
       "m/s^2/sqrt(Hz)"},
      {sensor.accelerometer_random_walk, "accelerometer_random_walk", used.acc_bias_random_walk,
       "acc_bias_random_walk", "m/s^3/sqrt(Hz)"},
  };
  std::vector<std::string> lines;
  for (const Figure& f : figures) {
    if (!f.sensor || !(*f.sensor > 0)) continue;
    const double ratio = f.used / *f.sensor;
    if (ratio <= factor && ratio >= 1 / factor) continue;
    const std::string how = ratio > 1 ? fmt::format("{:.3g}x above", ratio)
                                      : (ratio > 0 ? fmt::format("{:.3g}x below", 1 / ratio) : std::string("0, below"));
    lines.push_back(fmt::format(
        "IMU noise: odometry.imu.{} is {:g} [{}] ({}), {} the {} {:g} of {}; the estimators weigh the IMU by the "
        "config's figure (set odometry.imu.{} if the sensor's is right)",
        f.config_key, f.used, f.unit, config_name, how, f.sensor_key, *f.sensor, sensor.file, f.config_key));
  }
  return lines;
}

}  // namespace drover::io
