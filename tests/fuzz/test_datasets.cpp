// Fuzzing the EuRoC reader (data.csv, sensor.yaml, ground truth, PNGs), the simulator folder reader and the ROS1 bag
// reader: mutated inputs must read cleanly or end in one short io::IoError naming the file -- never another
// exception, a crash, a hang or non-finite data (reader_fuzz.hpp).
#include <gtest/gtest.h>

#include "fuzz/fixtures.hpp"
#include "fuzz/reader_fuzz.hpp"
#include "io/dataset.hpp"
#include "io/fixtures/bag_fixtures.hpp"

namespace drover::test::fuzz {
namespace {

std::string readDataset(const fs::path& dir, const std::string& format, const io::DatasetOptions& o = {}) {
  auto reader = io::openDataset(dir.string(), format, o);
  return checkStream(*reader, format != "bag");
}

TEST(FuzzEuroc, MutatedSequencesReadCleanlyOrFailWithOneIoErrorNamingTheFile) {
  ReaderTarget t;
  t.name = "euroc";
  t.write_fixture = [](const fs::path& root) { writeEurocSequence(root / "seq"); };
  t.files = {{"seq/mav0/imu0/data.csv"},
             {"seq/mav0/imu0/data.csv"},
             {"seq/mav0/cam0/data.csv"},
             {"seq/mav0/imu0/sensor.yaml"},
             {"seq/mav0/cam0/sensor.yaml"},
             {"seq/mav0/cam0/sensor.yaml"},
             {"seq/mav0/state_groundtruth_estimate0/data.csv"},
             {"seq/mav0/cam0/data/1403636579040000000.png", true, 1}};
  t.read = [](const fs::path& root) { return readDataset(root / "seq", "euroc"); };
  runCampaign(t, 400);
}

TEST(FuzzSim, MutatedSimulatorFoldersReadCleanlyOrFailWithOneIoErrorNamingTheFile) {
  ReaderTarget t;
  t.name = "sim";
  t.write_fixture = [](const fs::path& root) { writeSimDataset(root / "ds"); };
  t.files = {{"ds/calibration.yaml"},
             {"ds/calibration.yaml"},
             {"ds/imu.csv"},
             {"ds/lidar/timestamps.csv"},
             {"ds/camera/timestamps.csv"},
             {"ds/groundtruth.txt"},
             {"ds/scenario.json"},
             {"ds/lidar/000001.bin", true, io::kSimPointBytes},
             {"ds/lidar/000003.bin", true, io::kSimPointBytes},
             {"ds/camera/000001.png", true, 1}};
  t.read = [](const fs::path& root) { return readDataset(root / "ds", "sim"); };
  runCampaign(t, 400);
}

io::DatasetOptions bagTopics() {
  io::DatasetOptions o;
  o.lidar_topic = "/velodyne_points";
  o.imu_topic = "/imu_raw";
  o.image_topic = "/cam/png";
  return o;
}

class FuzzBag : public ::testing::TestWithParam<const char*> {};

TEST_P(FuzzBag, MutatedBagsReadCleanlyOrFailWithOneIoErrorNamingTheFile) {
  ReaderTarget t;
  const std::string compression = GetParam();
  t.name = "bag " + compression;
  t.write_fixture = [compression](const fs::path& root) {
    fs::create_directories(root);
    fs::copy_file(BagFixtures::get().bag(compression), root / "fixture.bag");
  };
  t.files = {{"fixture.bag", true, 4}};
  t.read = [](const fs::path& root) { return readDataset(root / "fixture.bag", "bag", bagTopics()); };
  runCampaign(t, 300);
}

INSTANTIATE_TEST_SUITE_P(Compressions, FuzzBag, ::testing::Values("none", "lz4"));

}  // namespace
}  // namespace drover::test::fuzz
