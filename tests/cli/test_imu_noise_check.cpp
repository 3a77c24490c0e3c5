// A platform config's IMU noise held against the figures a EuRoC sequence gives for its IMU: a warning per figure
// that is off by more than io::kImuNoiseReportFactor, naming both files, both keys and both values.
#include <gtest/gtest.h>

#include <string>

#include "io/odometry/imu_noise_check.hpp"
#include "support/cli.hpp"
#include "support/edited_config.hpp"
#include "support/shared_data.hpp"
#include "support/temp_dir.hpp"

namespace drover::io {
namespace {

using test::contains;

EurocImuNoise adis16448() {  // EuRoC's imu0/sensor.yaml
  EurocImuNoise n;
  n.file = "V1_01/mav0/imu0/sensor.yaml";
  n.gyroscope_noise_density = 1.6968e-4;
  n.gyroscope_random_walk = 1.9393e-5;
  n.accelerometer_noise_density = 2.0e-3;
  n.accelerometer_random_walk = 3.0e-3;
  return n;
}

imu::PreintegrationConfig sameAs(const EurocImuNoise& n) {
  imu::PreintegrationConfig c;
  c.gyro_noise_density = *n.gyroscope_noise_density;
  c.gyro_bias_random_walk = *n.gyroscope_random_walk;
  c.acc_noise_density = *n.accelerometer_noise_density;
  c.acc_bias_random_walk = *n.accelerometer_random_walk;
  return c;
}

TEST(ImuNoiseCheck, AConfigWithTheSensorsFiguresOrWithinTheFactorOfThemIsNotReported) {
  imu::PreintegrationConfig c = sameAs(adis16448());
  EXPECT_TRUE(imuNoiseDisagreements(adis16448(), c, "euroc.yaml").empty());
  c.acc_noise_density *= 4.9;  // a margin
  c.gyro_bias_random_walk /= 4.9;
  EXPECT_TRUE(imuNoiseDisagreements(adis16448(), c, "euroc.yaml").empty());
}

// The defect this check is for: config/euroc.yaml without an imu section ran the ADIS16448 with the farm robot's
// accelerometer bias walk, 10x below the sensor's.
TEST(ImuNoiseCheck, TheFarmRobotsBiasWalkOnEurocIsReportedWithBothFilesKeysAndValues) {
  imu::PreintegrationConfig c = sameAs(adis16448());
  c.acc_bias_random_walk = 3.0e-4;
  const std::vector<std::string> lines = imuNoiseDisagreements(adis16448(), c, "built-in default");
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_TRUE(contains(lines[0], "odometry.imu.acc_bias_random_walk is 0.0003 [m/s^3/sqrt(Hz)] (built-in default), "
                                 "10x below the accelerometer_random_walk 0.003 of V1_01/mav0/imu0/sensor.yaml"))
      << lines[0];
}

TEST(ImuNoiseCheck, EveryFigureIsComparedEitherWayAndAZeroInTheConfigIsReported) {
  imu::PreintegrationConfig c = sameAs(adis16448());
  c.gyro_noise_density *= 24;     // VINS-Mono's EuRoC config inflates it 24x
  c.gyro_bias_random_walk /= 10;  // and takes the walk 10x below
  c.acc_noise_density *= 40;
  c.acc_bias_random_walk = 0;
  const std::vector<std::string> lines = imuNoiseDisagreements(adis16448(), c, "vins.yaml");
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_TRUE(contains(lines[0], "gyro_noise_density") && contains(lines[0], "24x above")) << lines[0];
  EXPECT_TRUE(contains(lines[1], "gyro_bias_random_walk") && contains(lines[1], "10x below")) << lines[1];
  EXPECT_TRUE(contains(lines[2], "acc_noise_density") && contains(lines[2], "40x above")) << lines[2];
  EXPECT_TRUE(contains(lines[3], "acc_bias_random_walk is 0 ") && contains(lines[3], "0, below")) << lines[3];
}

TEST(ImuNoiseCheck, AFigureTheSensorFileLeavesOutOrGivesAsZeroIsNotCompared) {
  EurocImuNoise n = adis16448();
  imu::PreintegrationConfig c = sameAs(n);
  n.gyroscope_noise_density.reset();
  n.accelerometer_random_walk = 0.0;
  c.gyro_noise_density = 1.0;  // would be 5900x
  c.acc_bias_random_walk = 1.0;
  EXPECT_TRUE(imuNoiseDisagreements(n, c, "x.yaml").empty());
}

// As a user meets it: `drover run` on the EuRoC snippet (the camera off, so it ends at once for want of lidar).
TEST(ImuNoiseCheck, DroverRunOnEurocWarnsOfAConfigWithTheFarmRobotsBiasWalkAndNotOfTheShippedOne) {
  const std::filesystem::path seq = test::sharedData("euroc/V1_01_easy_micro");
  DROVER_REQUIRE_SHARED(seq);
  test::TempDir dir;
  const std::string farm_walk = test::editedConfig(
      "euroc.yaml", dir.path(), {{"acc_bias_random_walk: 3.0e-3", "acc_bias_random_walk: 3.0e-4"}});
  const std::string args = "run " + seq.string() + " --format euroc --no-camera --out " + (dir / "o").string();
  const test::CliResult edited = test::runDrover(args + " --config " + farm_walk);
  EXPECT_TRUE(contains(edited.output, "IMU noise: odometry.imu.acc_bias_random_walk is 0.0003 [m/s^3/sqrt(Hz)] (" +
                                          farm_walk + "), 10x below the accelerometer_random_walk 0.003 of "))
      << edited.output;
  EXPECT_TRUE(contains(edited.output, "V1_01_easy_micro/mav0/imu0/sensor.yaml; the estimators weigh the IMU by"))
      << edited.output;
  const test::CliResult shipped =
      test::runDrover(args + " --config " + std::string(DROVER_SOURCE_DIR) + "/config/euroc.yaml");
  EXPECT_TRUE(contains(shipped.output, "has no lidar scans")) << shipped.output;  // it ran as far as the other
  EXPECT_FALSE(contains(shipped.output, "IMU noise")) << shipped.output;
}

}  // namespace
}  // namespace drover::io
