// The IMU's stream problems become warning lines: each kind says what happened and when, and a flood of one kind is
// shown a few times and then only counted.
#include <gtest/gtest.h>

#include <string>

#include "pipeline/imu_stream_notices.hpp"

namespace drover::pipeline {
namespace {

using imu::SampleStatus;

ImuSample sampleAt(double t_s, double ax = 0.0) {
  ImuSample s;
  s.t = fromSeconds(t_s);
  s.acc_imu = Eigen::Vector3d(ax, 0, 9.81);
  return s;
}

bool has(const std::optional<std::string>& line, const std::string& part) {
  return line && line->find(part) != std::string::npos;
}

TEST(ImuStreamNotices, ANormalSampleSaysNothing) {
  ImuStreamNotices n;
  EXPECT_FALSE(n.onSample(sampleAt(1.0), SampleStatus::kAccepted, fromSeconds(0.995)));
}

TEST(ImuStreamNotices, AGapSaysItsLengthAndTheSampleTime) {
  ImuStreamNotices n;
  const auto line = n.onSample(sampleAt(2.5), SampleStatus::kAcceptedAfterGap, fromSeconds(2.0));
  EXPECT_TRUE(has(line, "IMU gap of 0.500 s before the sample at 2.500000 s")) << line.value_or("");
}

TEST(ImuStreamNotices, ASpikeSaysItsMagnitudes) {
  ImuStreamNotices n;
  const auto line = n.onSample(sampleAt(3.0, 400.0), SampleStatus::kDroppedSpike, fromSeconds(2.995));
  EXPECT_TRUE(has(line, "IMU sample at 3.000000 s dropped: spike (|a| = 400.1 m/s^2")) << line.value_or("");
}

TEST(ImuStreamNotices, NonFiniteAndOutOfOrderSamplesSayWhy) {
  ImuStreamNotices n;
  EXPECT_TRUE(has(n.onSample(sampleAt(1.0), SampleStatus::kDroppedNonFinite, {}), "non-finite"));
  EXPECT_TRUE(has(n.onSample(sampleAt(1.0), SampleStatus::kDroppedOutOfOrder, fromSeconds(1.5)),
                  "not after the previous sample's (1.500000 s)"));
}

TEST(ImuStreamNotices, AFloodOfOneKindIsShownFiveTimesThenOnceSaidToBeCountedOnlyWhileOtherKindsStillShow) {
  ImuStreamNotices n;
  int shown = 0, suppressed = 0;
  for (int i = 0; i < 100; ++i) {
    const auto line = n.onSample(sampleAt(i, 500.0), SampleStatus::kDroppedSpike, {});
    if (has(line, "dropped: spike")) ++shown;
    if (has(line, "are not shown")) ++suppressed;
  }
  EXPECT_EQ(shown, static_cast<int>(ImuStreamNotices::kPerKind));
  EXPECT_EQ(suppressed, 1);
  EXPECT_TRUE(has(n.onSample(sampleAt(200.0), SampleStatus::kAcceptedAfterGap, fromSeconds(199.0)), "IMU gap"));
}

}  // namespace
}  // namespace drover::pipeline
