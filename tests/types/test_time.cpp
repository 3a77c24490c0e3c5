#include <gtest/gtest.h>

#include "types/measurement.hpp"

using namespace drover;

TEST(Time, SecondsRoundTripToTheNanosecondAtEpochScale) {
  const Time t = 1403715273262142976;  // an EuRoC stamp
  EXPECT_NEAR(static_cast<double>(fromSeconds(toSeconds(t)) - t), 0.0, 256.0);  // double has ~52 bits: 238 ns here
  EXPECT_EQ(fromSeconds(1.5), 1'500'000'000);
  EXPECT_EQ(fromSeconds(-0.000000001), -1);
  EXPECT_EQ(fromSeconds(0.1037359), 103'735'900);
}

TEST(Measurement, TimeIsReadFromEveryAlternative) {
  ImuSample imu;
  imu.t = 5;
  LidarScan scan;
  scan.t = 7;
  CameraFrame frame;
  frame.t = 9;
  EXPECT_EQ(measurementTime(Measurement{imu}), 5);
  EXPECT_EQ(measurementTime(Measurement{scan}), 7);
  EXPECT_EQ(measurementTime(Measurement{frame}), 9);
}
