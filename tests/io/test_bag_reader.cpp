// ROS bag reader on bags written by python3-rosbag (tests/io/fixtures/write_bags.py): every value read back is
// compared with what the script wrote. The script writes the messages out of record-time order, with header
// stamps lagging record times by topic-dependent latencies, so only a reader that follows the index and reorders
// by stamp returns them in the expected order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "io/bag_reader.hpp"
#include "io/error.hpp"
#include "io/fixtures/bag_fixtures.hpp"

namespace drover::io {
namespace {

using nlohmann::json;
using test::BagFixtures;

const json& expectedTopic(const std::string& topic) { return BagFixtures::get().expected()["topics"][topic]; }

DatasetOptions topics(const std::string& lidar, const std::string& imu, const std::string& image) {
  DatasetOptions o;
  o.lidar_topic = lidar;
  o.imu_topic = imu;
  o.image_topic = image;
  return o;
}

std::vector<Measurement> readAll(const std::string& compression, const DatasetOptions& o) {
  BagReader reader(BagFixtures::get().bag(compression).string(), o);
  std::vector<Measurement> out;
  while (auto m = reader.next()) out.push_back(std::move(*m));
  return out;
}

void expectScan(const LidarScan& s, const json& e) {
  EXPECT_EQ(s.t, e["t"].get<Time>());
  EXPECT_EQ(s.t_end, e["t_end"].get<Time>());
  EXPECT_EQ(s.has_time, e["has_time"].get<bool>());
  EXPECT_EQ(s.has_ring, e["has_ring"].get<bool>());
  ASSERT_EQ(s.points.size(), e["points"].size());
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const json& p = e["points"][i];
    const LidarPoint& q = s.points[i];
    EXPECT_EQ(q.x, p["x"].get<float>()) << "point " << i;
    EXPECT_EQ(q.y, p["y"].get<float>()) << "point " << i;
    EXPECT_EQ(q.z, p["z"].get<float>()) << "point " << i;
    EXPECT_EQ(q.intensity, p["intensity"].get<float>()) << "point " << i;
    EXPECT_EQ(q.ring, p["ring"].get<int>()) << "point " << i;
    EXPECT_EQ(q.time_offset, p["time_offset"].get<float>()) << "point " << i;
    EXPECT_GE(q.time_offset, 0.0f) << "point " << i;
  }
}

void expectImu(const ImuSample& s, const json& e) {
  EXPECT_EQ(s.t, e["t"].get<Time>());
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(s.omega_imu[i], e["omega"][i].get<double>());
    EXPECT_EQ(s.acc_imu[i], e["acc"][i].get<double>());
  }
  ASSERT_EQ(s.q_world_imu.has_value(), !e["q"].is_null()) << "IMU at " << s.t;
  if (s.q_world_imu) {
    EXPECT_NEAR(s.q_world_imu->w(), e["q"][0].get<double>(), 1e-12);
    EXPECT_NEAR(s.q_world_imu->x(), e["q"][1].get<double>(), 1e-12);
    EXPECT_NEAR(s.q_world_imu->y(), e["q"][2].get<double>(), 1e-12);
    EXPECT_NEAR(s.q_world_imu->z(), e["q"][3].get<double>(), 1e-12);
  }
}

void expectImage(const CameraFrame& f, const json& e) {
  EXPECT_EQ(f.t, e["t"].get<Time>());
  ASSERT_EQ(f.image.width, e["width"].get<int>());
  ASSERT_EQ(f.image.height, e["height"].get<int>());
  ASSERT_EQ(f.image.channels, e["channels"].get<int>());
  const auto want = e["data"].get<std::vector<int>>();
  ASSERT_EQ(f.image.data.size(), want.size());
  if (e.value("exact", true)) {
    EXPECT_EQ(std::vector<int>(f.image.data.begin(), f.image.data.end()), want);
    return;
  }
  // JPEG is lossy: pixels close to the original on average and everywhere.
  double sum = 0;
  int worst = 0;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const int d = std::abs(static_cast<int>(f.image.data[i]) - want[i]);
    sum += d;
    worst = std::max(worst, d);
  }
  EXPECT_LT(sum / static_cast<double>(want.size()), 4.0);
  EXPECT_LE(worst, 24);
}

// The expected stream for a topic configuration: all messages of the three topics ordered by time.
struct Expected {
  Time t;
  int kind;  // 0 lidar, 1 imu, 2 image
  const json* value;
};
std::vector<Expected> expectedStream(const DatasetOptions& o) {
  std::vector<Expected> out;
  const std::string names[] = {o.lidar_topic, o.imu_topic, o.image_topic};
  for (int k = 0; k < 3; ++k)
    for (const json& e : expectedTopic(names[k])) out.push_back({e["t"].get<Time>(), k, &e});
  std::sort(out.begin(), out.end(), [](const Expected& a, const Expected& b) { return a.t < b.t; });
  return out;
}

void expectStream(const std::string& compression, const DatasetOptions& o) {
  const std::vector<Measurement> got = readAll(compression, o);
  const std::vector<Expected> want = expectedStream(o);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    SCOPED_TRACE("measurement " + std::to_string(i));
    const int kind = std::holds_alternative<LidarScan>(got[i]) ? 0 : std::holds_alternative<ImuSample>(got[i]) ? 1 : 2;
    ASSERT_EQ(kind, want[i].kind);
    if (want[i].kind == 0) expectScan(std::get<LidarScan>(got[i]), *want[i].value);
    if (want[i].kind == 1) expectImu(std::get<ImuSample>(got[i]), *want[i].value);
    if (want[i].kind == 2) expectImage(std::get<CameraFrame>(got[i]), *want[i].value);
  }
}

class BagReaderCompression : public ::testing::TestWithParam<std::string> {};

TEST_P(BagReaderCompression, ReturnsVelodyneImuAndBgrImagesExactlyInStampOrder) {
  expectStream(GetParam(), topics("/velodyne_points", "/imu_raw", "/cam/bgr"));
}

TEST_P(BagReaderCompression, ReturnsOusterCloudsWithNanosecondPointTimesAndRgbImagesAsBgr) {
  expectStream(GetParam(), topics("/ouster/points", "/imu_raw", "/cam/rgb"));
}

TEST_P(BagReaderCompression, ReadsFloat64CloudsWithoutRingOrTimeAndPaddedMono8Images) {
  expectStream(GetParam(), topics("/points_f64", "/imu_raw", "/cam/mono"));
}

TEST_P(BagReaderCompression, ReadsUint16IntensityUint8RingTimestampFieldAndPngImages) {
  expectStream(GetParam(), topics("/points_u16", "/imu_raw", "/cam/png"));
}

TEST_P(BagReaderCompression, DecodesJpegImagesToApproximatelyTheWrittenPixels) {
  expectStream(GetParam(), topics("/velodyne_points", "/imu_raw", "/cam/jpeg"));
}

INSTANTIATE_TEST_SUITE_P(AllCompressions, BagReaderCompression, ::testing::Values("none", "bz2", "lz4"));

TEST(BagReader, DropsNanPointsOfOrganisedCloudsAndCountsThem) {
  BagReader reader(BagFixtures::get().bag("lz4").string(), topics("/ouster/points", "", ""));
  std::size_t want = 0;
  for (const json& e : expectedTopic("/ouster/points")) want += e["dropped"].get<std::size_t>();
  ASSERT_GT(want, 0u);
  std::size_t in_scans = 0;  // what drover run and drover info count
  while (auto m = reader.next()) in_scans += std::get<LidarScan>(*m).dropped_nonfinite;
  EXPECT_EQ(reader.stats().nonfinite_points_dropped, want);
  EXPECT_EQ(in_scans, want);
}

TEST(BagReader, SweepStampedAtItsEndStartsAtTheEarliestPointTime) {
  // The second Velodyne cloud carries offsets in [-0.1, 0) s: t moves back to its earliest point.
  const json& e = expectedTopic("/velodyne_points")[1];
  const std::vector<Measurement> got = readAll("none", topics("/velodyne_points", "", ""));
  ASSERT_EQ(got.size(), 3u);
  const auto& scan = std::get<LidarScan>(got[1]);
  EXPECT_EQ(scan.t, e["t"].get<Time>());
  EXPECT_NEAR(toSeconds(scan.t_end - scan.t), 0.0975, 1e-6);
  EXPECT_EQ(std::min_element(scan.points.begin(), scan.points.end(), [](auto& a, auto& b) {
              return a.time_offset < b.time_offset;
            })->time_offset, 0.0f);
}

TEST(BagReader, KeepsOnlyUnitOrientationsThatTheImuReports) {
  const std::vector<Measurement> got = readAll("bz2", topics("", "/imu_raw", ""));
  ASSERT_EQ(got.size(), 40u);
  int with = 0, without = 0;
  for (const Measurement& m : got) (std::get<ImuSample>(m).q_world_imu ? with : without)++;
  EXPECT_GT(with, 0);
  EXPECT_GT(without, 0);  // covariance -1, all-zero quaternion and far-from-unit quaternion cases
}

TEST(BagReader, SkipsDisabledSensors) {
  DatasetOptions o = topics("/velodyne_points", "/imu_raw", "/cam/bgr");
  o.load_imu = false;
  o.load_images = false;
  const std::vector<Measurement> got = readAll("lz4", o);
  ASSERT_EQ(got.size(), 3u);
  for (const Measurement& m : got) EXPECT_TRUE(std::holds_alternative<LidarScan>(m));
}

TEST(BagReader, WarnsAboutOneMissingTopicAndReadsTheOthers) {
  BagReader reader(BagFixtures::get().bag("none").string(), topics("/no_such_lidar", "/imu_raw", ""));
  ASSERT_EQ(reader.warnings().size(), 1u);
  EXPECT_NE(reader.warnings()[0].find("/no_such_lidar"), std::string::npos);
  EXPECT_NE(reader.describe().find("/no_such_lidar"), std::string::npos);
  int n = 0;
  while (reader.next()) ++n;
  EXPECT_EQ(n, 40);
}

TEST(BagReader, ListsTheBagsTopicsWhenNoConfiguredTopicExists) {
  const std::string bag = BagFixtures::get().bag("none").string();
  try {
    BagReader reader(bag, topics("/a", "/b", "/c"));
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(bag), std::string::npos) << what;
    for (const json& topic : BagFixtures::get().expected()["all_topics"])
      EXPECT_NE(what.find(topic.get<std::string>()), std::string::npos) << what;
  }
}

TEST(BagReader, RejectsATopicOfTheWrongMessageType) {
  try {
    BagReader reader(BagFixtures::get().bag("none").string(), topics("", "/velodyne_points", ""));
    FAIL() << "expected IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("sensor_msgs/PointCloud2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sensor_msgs/Imu"), std::string::npos) << e.what();
  }
}

TEST(BagReader, NamesBagTopicAndMessageOfMalformedMessages) {
  const std::string bag = BagFixtures::get().bag("lz4").string();
  for (const json& err : BagFixtures::get().expected()["errors"]) {
    const std::string topic = err["topic"].get<std::string>();
    SCOPED_TRACE(topic);
    const bool imu = err.value("kind", "") == "imu";
    BagReader reader(bag, imu ? topics("", topic, "") : topics(topic, "", ""));
    int read = 0;
    try {
      while (reader.next()) ++read;
      ADD_FAILURE() << "expected IoError";
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(bag), std::string::npos) << what;
      EXPECT_NE(what.find("topic " + topic + " message " + std::to_string(err["message"].get<int>()) + ","),
                std::string::npos)
          << what;
      EXPECT_NE(what.find(err["contains"].get<std::string>()), std::string::npos) << what;
    }
  }
}

TEST(BagReader, DropsAnImuMessageWithARepeatedBackwardsOrNanReadingWithAWarningNamingIt) {
  const std::string bag = BagFixtures::get().bag("lz4").string();
  for (const json& drop : BagFixtures::get().expected()["drops"]) {
    const std::string topic = drop["topic"].get<std::string>();
    SCOPED_TRACE(topic);
    BagReader reader(bag, topics("", topic, ""));
    std::vector<Time> t;
    while (auto m = reader.next()) t.push_back(measurementTime(*m));
    EXPECT_EQ(t, drop["kept"].get<std::vector<Time>>());
    ASSERT_EQ(reader.drops().measurements, 1u);
    const std::string& notice = reader.drops().notices.at(0);
    EXPECT_NE(notice.find(bag + " (topic " + topic + " message " + std::to_string(drop["message"].get<int>()) + ","),
              std::string::npos)
        << notice;
    EXPECT_NE(notice.find("dropped"), std::string::npos) << notice;
    EXPECT_NE(notice.find(drop["contains"].get<std::string>()), std::string::npos) << notice;
  }
}

TEST(BagReader, OpenBagReturnsAReaderDescribingTheBag) {
  const std::string bag = BagFixtures::get().bag("bz2").string();
  const auto reader = openBag(bag, topics("/velodyne_points", "/imu_raw", "/cam/png"));
  EXPECT_NE(reader->describe().find(bag), std::string::npos);
  EXPECT_TRUE(reader->groundTruth().poses.empty());
  EXPECT_TRUE(reader->next().has_value());
}

}  // namespace
}  // namespace drover::io
