// Injected sensor faults (sim/sensor_faults.hpp): each removes or changes exactly the samples in its window, and
// everything outside the windows is identical to the run without faults (same noise: faults never renumber).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

#include "io/sim_dataset.hpp"
#include "sim/sensor_faults.hpp"
#include "sim/simulator.hpp"
#include "small_scenario.hpp"
#include "support/units.hpp"

namespace drover::sim {
namespace {

using fixture::runAll;
using fixture::sameMeasurement;
using fixture::smallConfig;
using fixture::smallScenario;

using ::drover::test::kMs;

double meanGrey(const CameraFrame& f) {
  const double sum = std::accumulate(f.image.data.begin(), f.image.data.end(), 0.0);
  return sum / static_cast<double>(f.image.data.size());
}

// Grey-level gradient energy: the texture the tracker needs (mean |dI/du| over the image).
double meanGradient(const CameraFrame& f) {
  const Image& im = f.image;
  double sum = 0;
  for (int v = 0; v < im.height; ++v)
    for (int u = 1; u < im.width; ++u)
      sum += std::abs(static_cast<int>(im.data[static_cast<std::size_t>(v * im.width + u)]) -
                      static_cast<int>(im.data[static_cast<std::size_t>(v * im.width + u - 1)]));
  return sum / (im.height * (im.width - 1));
}

TEST(SensorFaults, NamesRoundTripAndBadWindowsAreRefused) {
  for (const std::string& name : faultNames()) EXPECT_EQ(faultName(*faultKind(name)), name);
  EXPECT_FALSE(faultKind("camera-off").has_value());
  EXPECT_TRUE(validateFaults({{FaultKind::kImuGap, 100 * kMs, 600 * kMs}}).empty());
  EXPECT_NE(validateFaults({{FaultKind::kImuGap, 600 * kMs, 600 * kMs}}).find("imu-gap"), std::string::npos);
  SimulatorConfig c = smallConfig();
  c.faults = {{FaultKind::kLidarDropout, 0, 601 * kNanosPerSecond}};
  EXPECT_NE(c.validate().find("lidar-dropout"), std::string::npos);
}

TEST(SensorFaults, ImuGapAndLidarDropoutRemoveExactlyTheirWindowAndLeaveEverythingElseIdentical) {
  const Scenario s = smallScenario();
  SimulatorConfig faulted = smallConfig();
  faulted.faults = {{FaultKind::kImuGap, 500 * kMs, 1000 * kMs}, {FaultKind::kLidarDropout, 1250 * kMs, 1450 * kMs}};
  const std::vector<Measurement> clean = runAll(Simulator(s, smallConfig(), 5));
  const Simulator sim(s, faulted, 5);
  const std::vector<Measurement> with = runAll(sim);
  std::vector<Measurement> expected;
  for (const Measurement& m : clean) {
    if (const auto* i = std::get_if<ImuSample>(&m); i && i->t >= 500 * kMs && i->t < 1000 * kMs) continue;
    // Sweeps of 0.1 s starting at 1.2, 1.3 and 1.4 s overlap [1.25, 1.45) s.
    if (const auto* l = std::get_if<LidarScan>(&m); l && l->t >= 1200 * kMs && l->t <= 1400 * kMs) continue;
    expected.push_back(m);
  }
  ASSERT_EQ(with.size(), expected.size());
  for (std::size_t i = 0; i < with.size(); ++i) ASSERT_TRUE(sameMeasurement(with[i], expected[i])) << i;
  const Simulator::Counts n = sim.expectedCounts();
  EXPECT_EQ(n.imu, 401u - 100u);  // 200 Hz: samples at 0.500 ... 0.995 s
  EXPECT_EQ(n.lidar, 20u - 3u);
  EXPECT_EQ(n.camera, 30u);
}

std::vector<CameraFrame> framesOf(const Scenario& s, const SimulatorConfig& c) {
  std::vector<CameraFrame> out;
  for (Measurement& m : runAll(Simulator(s, c, 9)))
    if (auto* f = std::get_if<CameraFrame>(&m)) out.push_back(std::move(*f));
  return out;
}

TEST(SensorFaults, ABlackoutIsDarkThenOverexposedUntilTheAutoExposureSettles) {
  const Scenario s = smallScenario();
  SimulatorConfig faulted = smallConfig();
  faulted.faults = {{FaultKind::kCameraBlackout, 300 * kMs, 800 * kMs}};
  const std::vector<CameraFrame> clean = framesOf(s, smallConfig()), with = framesOf(s, faulted);
  ASSERT_EQ(clean.size(), with.size());
  const Time offset = smallConfig().camera_time_offset;
  bool after = false;
  for (std::size_t k = 0; k < with.size(); ++k) {
    const Time t = with[k].t + offset;  // true mid-exposure time
    if (t < 300 * kMs) {
      EXPECT_TRUE(sameMeasurement(Measurement(with[k]), Measurement(clean[k]))) << "frame " << k;
    } else if (t < 800 * kMs) {
      EXPECT_LT(meanGrey(with[k]), 3.0) << "frame " << k << ": no light, read noise only";
    } else if (!after) {
      after = true;  // the auto exposure opened up in the dark
      EXPECT_GT(meanGrey(with[k]), meanGrey(clean[k]) + 20.0) << "frame " << k;
    }
  }
  EXPECT_TRUE(after);
}

TEST(SensorFaults, ATexturelessStretchKeepsTheBrightnessButLosesTheTexture) {
  const Scenario s = smallScenario();
  SimulatorConfig faulted = smallConfig();
  faulted.faults = {{FaultKind::kTextureless, 700 * kMs, 1200 * kMs}};
  const std::vector<CameraFrame> clean = framesOf(s, smallConfig()), with = framesOf(s, faulted);
  ASSERT_EQ(clean.size(), with.size());
  const Time offset = smallConfig().camera_time_offset;
  int inside = 0;
  for (std::size_t k = 0; k < with.size(); ++k) {
    const Time t = with[k].t + offset;
    if (t < 700 * kMs) {
      EXPECT_TRUE(sameMeasurement(Measurement(with[k]), Measurement(clean[k]))) << "frame " << k;
    } else if (t < 1200 * kMs) {
      ++inside;
      EXPECT_LT(meanGradient(with[k]), 0.5 * meanGradient(clean[k])) << "frame " << k;
      EXPECT_NEAR(meanGrey(with[k]), meanGrey(clean[k]), 0.25 * meanGrey(clean[k])) << "frame " << k;
    }
  }
  EXPECT_EQ(inside, 7);  // 15 Hz over 0.5 s
}

TEST(SensorFaults, TheDatasetDescriptionListsTheFaultsForScenarioJson) {
  const Scenario s = smallScenario();
  SimulatorConfig c = smallConfig();
  c.faults = {{FaultKind::kTextureless, 1200 * kMs, 1700 * kMs}};
  const io::SimDatasetDescription d = Simulator(s, c, 1).datasetDescription();
  ASSERT_EQ(d.scenario.faults.size(), 1u);
  EXPECT_EQ(d.scenario.faults[0].condition, "textureless");
  EXPECT_EQ(d.scenario.faults[0].start, 1200 * kMs);
  EXPECT_EQ(d.scenario.faults[0].end, 1700 * kMs);
  EXPECT_TRUE(Simulator(s, smallConfig(), 1).datasetDescription().scenario.faults.empty());
}

}  // namespace
}  // namespace drover::sim
