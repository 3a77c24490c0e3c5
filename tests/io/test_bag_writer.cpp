// Drover's ROS1 bag writer, checked two ways on the same bags: Drover's own reader gets back every stamp, point,
// IMU value, image byte and ground-truth pose written; Debian's python3-rosbag (the reference implementation,
// tests/io/fixtures/read_bag.py) reads the topics, types and counts, deserializes every message with classes built
// from the definitions in the connection headers (whose md5sums it recomputes) and `rosbag info` accepts the bag.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <tuple>
#include <vector>

#include "io/bag_reader.hpp"
#include "io/bag_writer.hpp"
#include "io/error.hpp"
#include "io/ros_message_definitions.hpp"
#include "io/ros_serialize.hpp"
#include "io/fixtures/read_bag.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"
#include "support/units.hpp"

namespace drover::io {
namespace {
namespace fs = std::filesystem;
using test::TempDir;

constexpr Time kWriterT0 = Time{1'600'000'000} * kNanosPerSecond + 123'456'789;  // any Unix time with odd nanoseconds
using ::drover::test::kMs;

LidarScan makeScan(Time t, int k) {
  LidarScan s;
  s.t = t;
  s.has_time = s.has_ring = true;
  for (int i = 0; i < 200; ++i) {
    LidarPoint p;
    p.x = 1.0f + 0.5f * static_cast<float>(i) + static_cast<float>(k);
    p.y = -0.25f * static_cast<float>(i);
    p.z = 0.125f * static_cast<float>(k) - 0.3f;
    p.intensity = static_cast<float>(i % 256);
    p.ring = static_cast<std::uint16_t>(i % 16);
    p.time_offset = static_cast<float>(i) * 4.9e-4f;  // the last point 97.5 ms after the stamp
    s.points.push_back(p);
  }
  s.t_end = t + static_cast<Time>(std::llround(static_cast<double>(s.points.back().time_offset) * 1e9));
  return s;
}

ImuSample makeImu(Time t, int k) {
  ImuSample s;
  s.t = t;
  s.omega_imu = {0.01 * k, -0.02, 0.3 + 1e-3 * k};
  s.acc_imu = {0.1, -0.2 * k, 9.81};
  if (k % 2 == 0) s.q_world_imu = Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitZ()));
  return s;
}

CameraFrame makeFrame(Time t, int k) {
  CameraFrame f;
  f.t = t;
  f.image.width = 40;
  f.image.height = 30;
  f.image.channels = k % 2 == 0 ? 1 : 3;  // mono8 and bgr8
  for (int i = 0; i < 40 * 30 * f.image.channels; ++i) f.image.data.push_back(static_cast<std::uint8_t>(i * 7 + k));
  return f;
}

ros::Odometry makeOdometry(Time t, int k) {
  ros::Odometry o;
  o.t = t;
  o.frame_id = "world";
  o.child_frame_id = "imu";
  o.T_frame_child.linear() = Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d(0.1, 0.2, 1).normalized()).matrix();
  o.T_frame_child.translation() = Eigen::Vector3d(0.1 * k, -0.05 * k, 0.4);
  o.linear = {1.0, 0.0, 0.01 * k};
  o.angular = {0.0, 0.0, 0.2};
  return o;
}

struct Written {
  std::vector<LidarScan> scans;
  std::vector<ImuSample> imu;
  std::vector<CameraFrame> frames;
  std::vector<ros::Odometry> gt;
  std::size_t chunks = 0;
};

// One second: IMU 100 Hz, lidar 10 Hz (recorded at its last point, as a driver publishes it), camera 5 Hz, ground
// truth 50 Hz; messages written in record-time order, so the lidar's lands after the IMU samples it spans.
Written writeTestBag(const fs::path& path, std::uint32_t chunk_bytes) {
  Written w;
  bag::WriterOptions options;
  options.chunk_bytes = chunk_bytes;
  bag::BagWriter writer(path.string(), options);
  const std::uint32_t lidar = writer.addConnection("/points_raw", ros::pointCloud2Type());
  const std::uint32_t imu = writer.addConnection("/imu_raw", ros::imuType());
  const std::uint32_t image = writer.addConnection("/camera/image_raw", ros::imageType());
  const std::uint32_t gt = writer.addConnection("/ground_truth", ros::odometryType());
  std::vector<std::tuple<Time, int, std::uint32_t, std::string>> messages;  // record time, order, connection, data
  for (int k = 0; k < 100; ++k) {
    w.imu.push_back(makeImu(kWriterT0 + k * 10 * kMs, k));
    messages.emplace_back(w.imu.back().t, 1, imu, ros::serializeImu(w.imu.back(), k, "imu", {1e-6, 4e-4}));
  }
  for (int k = 0; k < 10; ++k) {
    w.scans.push_back(makeScan(kWriterT0 + k * 100 * kMs, k));
    messages.emplace_back(w.scans.back().t_end, 0, lidar, ros::serializePointCloud2(w.scans.back(), k, "lidar"));
  }
  for (int k = 0; k < 5; ++k) {
    w.frames.push_back(makeFrame(kWriterT0 + 5 * kMs + k * 200 * kMs, k));
    messages.emplace_back(w.frames.back().t, 2, image, ros::serializeImage(w.frames.back(), k, "camera"));
  }
  for (int k = 0; k < 50; ++k) {
    w.gt.push_back(makeOdometry(kWriterT0 + k * 20 * kMs, k));
    messages.emplace_back(w.gt.back().t, 3, gt, ros::serializeOdometry(w.gt.back(), k));
  }
  std::stable_sort(messages.begin(), messages.end(), [](const auto& a, const auto& b) {
    return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
  });
  for (const auto& [t, order, conn, data] : messages) writer.write(conn, t, data);
  writer.finish();
  w.chunks = writer.counts().chunks;
  return w;
}

DatasetOptions simTopics() {
  DatasetOptions o;
  o.lidar_topic = "/points_raw";
  o.imu_topic = "/imu_raw";
  o.image_topic = "/camera/image_raw";
  o.ground_truth_topic = "/ground_truth";
  return o;
}

void expectReadBack(const fs::path& path, const Written& w) {
  BagReader reader(path.string(), simTopics());
  EXPECT_TRUE(reader.warnings().empty()) << reader.describe();
  std::vector<LidarScan> scans;
  std::vector<ImuSample> imu;
  std::vector<CameraFrame> frames;
  Time last = 0;
  while (auto m = reader.next()) {
    EXPECT_GE(measurementTime(*m), last) << "the reader returns the stream in stamp order";
    last = measurementTime(*m);
    if (auto* s = std::get_if<LidarScan>(&*m)) scans.push_back(std::move(*s));
    if (auto* s = std::get_if<ImuSample>(&*m)) imu.push_back(*s);
    if (auto* f = std::get_if<CameraFrame>(&*m)) frames.push_back(std::move(*f));
  }
  ASSERT_EQ(scans.size(), w.scans.size());
  for (std::size_t k = 0; k < scans.size(); ++k) {
    EXPECT_EQ(scans[k].t, w.scans[k].t);
    EXPECT_EQ(scans[k].t_end, w.scans[k].t_end);
    EXPECT_TRUE(scans[k].has_time && scans[k].has_ring);
    ASSERT_EQ(scans[k].points.size(), w.scans[k].points.size());
    for (std::size_t i = 0; i < scans[k].points.size(); ++i) {
      const LidarPoint &a = scans[k].points[i], &b = w.scans[k].points[i];
      EXPECT_EQ(std::tie(a.x, a.y, a.z, a.intensity, a.ring), std::tie(b.x, b.y, b.z, b.intensity, b.ring));
      // float32 seconds -> ns -> float32: within a nanosecond.
      EXPECT_NEAR(a.time_offset, b.time_offset, 1e-9) << "scan " << k << " point " << i;
    }
  }
  ASSERT_EQ(imu.size(), w.imu.size());
  for (std::size_t k = 0; k < imu.size(); ++k) {
    EXPECT_EQ(imu[k].t, w.imu[k].t);
    EXPECT_EQ(imu[k].omega_imu, w.imu[k].omega_imu);
    EXPECT_EQ(imu[k].acc_imu, w.imu[k].acc_imu);
    ASSERT_EQ(imu[k].q_world_imu.has_value(), w.imu[k].q_world_imu.has_value()) << "sample " << k;
    if (imu[k].q_world_imu) {
      EXPECT_TRUE(imu[k].q_world_imu->isApprox(*w.imu[k].q_world_imu, 1e-12));
    }
  }
  ASSERT_EQ(frames.size(), w.frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_EQ(frames[k].t, w.frames[k].t);
    EXPECT_EQ(frames[k].image.channels, w.frames[k].image.channels);
    EXPECT_EQ(frames[k].image.data, w.frames[k].image.data);
  }
  const GroundTruth& gt = reader.groundTruth();
  EXPECT_EQ(gt.body_frame, "imu");
  ASSERT_EQ(gt.poses.size(), w.gt.size());
  for (std::size_t k = 0; k < gt.poses.size(); ++k) {
    EXPECT_EQ(gt.poses[k].t, w.gt[k].t);
    EXPECT_TRUE(gt.poses[k].T_world_body.isApprox(w.gt[k].T_frame_child, 1e-12)) << "pose " << k;
  }
}

TEST(BagWriter, DroversReaderGetsBackEveryStampPointImuValueImageByteAndGroundTruthPose) {
  TempDir dir;
  const Written w = writeTestBag(dir / "a.bag", 768 * 1024);
  EXPECT_FALSE(fs::exists(dir / "a.bag.partial"));
  expectReadBack(dir / "a.bag", w);
}

TEST(BagWriter, SmallChunksSplitTheBagIntoManyChunksWithTheSameMessages) {
  TempDir dir;
  const Written w = writeTestBag(dir / "a.bag", 4096);  // a scan (4.5 kB) or a frame fills a chunk on its own
  EXPECT_GT(w.chunks, 15u);
  expectReadBack(dir / "a.bag", w);
}

TEST(BagWriter, DebiansRosbagReadsTopicsCountsDefinitionsAndFieldsAndRosbagInfoAcceptsIt) {
  TempDir dir;
  const Written w = writeTestBag(dir / "a.bag", 16 * 1024);
  const nlohmann::json j = test::readBagWithRosbag(dir / "a.bag");
  ASSERT_FALSE(j.is_null());
  EXPECT_TRUE(j["rosbag_info_ok"].get<bool>()) << j["rosbag_info"];
  EXPECT_EQ(j["compression"], "none");
  EXPECT_EQ(j["chunks"].get<std::size_t>(), w.chunks);
  EXPECT_EQ(j["messages"], 165);
  EXPECT_EQ(j["read"], 165) << "every message deserializes";
  EXPECT_TRUE(j["read_in_time_order"].get<bool>());
  EXPECT_NEAR(j["start_ns"].get<double>(), static_cast<double>(kWriterT0), 1e3);
  const nlohmann::json& t = j["topics"];
  ASSERT_EQ(t.size(), 4u);
  const std::pair<const char*, const ros::MessageType*> types[] = {{"/points_raw", &ros::pointCloud2Type()},
                                                                   {"/imu_raw", &ros::imuType()},
                                                                   {"/camera/image_raw", &ros::imageType()},
                                                                   {"/ground_truth", &ros::odometryType()}};
  for (const auto& [topic, type] : types) {
    SCOPED_TRACE(topic);
    EXPECT_EQ(t[topic]["type"], std::string(type->name));
    EXPECT_EQ(t[topic]["md5sum"], std::string(type->md5sum));
    EXPECT_EQ(t[topic]["computed_md5sum"], std::string(type->md5sum)) << "the definition text matches its md5sum";
  }
  EXPECT_EQ(t["/points_raw"]["count"], 10);
  EXPECT_EQ(t["/imu_raw"]["count"], 100);
  EXPECT_EQ(t["/camera/image_raw"]["count"], 5);
  EXPECT_EQ(t["/ground_truth"]["count"], 50);

  const nlohmann::json& cloud = t["/points_raw"]["first"];
  EXPECT_EQ(cloud["header"]["stamp"].get<Time>(), kWriterT0);
  EXPECT_EQ(t["/points_raw"]["first_record_ns"].get<Time>(), w.scans[0].t_end) << "recorded at its last point";
  EXPECT_EQ(cloud["header"]["frame_id"], "lidar");
  EXPECT_EQ(cloud["height"], 1);
  EXPECT_EQ(cloud["width"], 200);
  EXPECT_EQ(cloud["point_step"], 22);
  EXPECT_EQ(cloud["row_step"], 200 * 22);
  std::vector<std::tuple<std::string, int, int>> fields;
  for (const auto& f : cloud["fields"]) fields.emplace_back(f["name"], f["offset"], f["datatype"]);
  const std::vector<std::tuple<std::string, int, int>> velodyne = {
      {"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"intensity", 12, 7}, {"ring", 16, 4}, {"time", 18, 7}};
  EXPECT_EQ(fields, velodyne);
  const nlohmann::json& p1 = t["/points_raw"]["first_points"][1];
  const LidarPoint& q1 = w.scans[0].points[1];
  EXPECT_EQ(p1["x"].get<float>(), q1.x);
  EXPECT_EQ(p1["y"].get<float>(), q1.y);
  EXPECT_EQ(p1["intensity"].get<float>(), q1.intensity);
  EXPECT_EQ(p1["ring"].get<int>(), q1.ring);
  EXPECT_EQ(p1["time"].get<float>(), q1.time_offset);

  const nlohmann::json& imu = t["/imu_raw"]["first"];
  EXPECT_EQ(imu["angular_velocity"]["z"].get<double>(), w.imu[0].omega_imu.z());
  EXPECT_EQ(imu["linear_acceleration"]["z"].get<double>(), w.imu[0].acc_imu.z());
  EXPECT_EQ(imu["angular_velocity_covariance"][0].get<double>(), 1e-6);
  EXPECT_EQ(imu["linear_acceleration_covariance"][8].get<double>(), 4e-4);
  EXPECT_EQ(imu["orientation"]["w"].get<double>(), 1.0);

  const nlohmann::json& image = t["/camera/image_raw"]["first"];
  EXPECT_EQ(image["encoding"], "mono8");
  EXPECT_EQ(image["width"], 40);
  EXPECT_EQ(image["step"], 40);
  EXPECT_EQ(image["data"]["len"], 40 * 30);
  EXPECT_EQ(image["data"]["head"][3].get<int>(), w.frames[0].image.data[3]);

  const nlohmann::json& odom = t["/ground_truth"]["first"];
  EXPECT_EQ(odom["header"]["frame_id"], "world");
  EXPECT_EQ(odom["child_frame_id"], "imu");
  EXPECT_EQ(odom["pose"]["pose"]["position"]["z"].get<double>(), 0.4);
  EXPECT_EQ(odom["twist"]["twist"]["linear"]["x"].get<double>(), 1.0);
}

TEST(BagWriter, TheKnownMd5sumsAreTheOnesTheReaderAccepts) {
  EXPECT_EQ(ros::pointCloud2Type().md5sum, ros::kPointCloud2Md5);
  EXPECT_EQ(ros::imuType().md5sum, ros::kImuMd5);
  EXPECT_EQ(ros::imageType().md5sum, ros::kImageMd5);
  EXPECT_EQ(ros::odometryType().md5sum, ros::kOdometryMd5);
  EXPECT_EQ(ros::odometryType().md5sum, "cd5e73d190d741a2f92e81eda573aca7");
}

TEST(BagWriter, ARecordTimeBeforeThePreviousOneIsRefusedNamingTheTopic) {
  TempDir dir;
  bag::BagWriter writer((dir / "a.bag").string());
  const std::uint32_t imu = writer.addConnection("/imu_raw", ros::imuType());
  writer.write(imu, kWriterT0, ros::serializeImu(makeImu(kWriterT0, 0), 0, "imu"));
  try {
    writer.write(imu, kWriterT0 - 1, ros::serializeImu(makeImu(kWriterT0 - 1, 1), 1, "imu"));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("/imu_raw"), std::string::npos) << e.what();
  }
  EXPECT_THROW(writer.write(imu, -1, "x"), std::invalid_argument);
  EXPECT_THROW(writer.addConnection("/imu_raw", ros::imuType()), std::invalid_argument) << "one connection a topic";
}

TEST(BagWriter, AWriterDestroyedBeforeFinishLeavesNeitherTheBagNorThePartialFile) {
  TempDir dir;
  {
    bag::BagWriter writer((dir / "a.bag").string());
    const std::uint32_t imu = writer.addConnection("/imu_raw", ros::imuType());
    writer.write(imu, kWriterT0, ros::serializeImu(makeImu(kWriterT0, 0), 0, "imu"));
    EXPECT_TRUE(fs::exists(dir / "a.bag.partial"));
  }
  EXPECT_FALSE(fs::exists(dir / "a.bag"));
  EXPECT_FALSE(fs::exists(dir / "a.bag.partial"));
}

TEST(BagWriter, ThePartialFileOfAKilledWriterIsAnUnindexedBagOfItsCompleteChunks) {
  TempDir dir;
  bag::WriterOptions options;
  options.chunk_bytes = 1000;  // an IMU message is ~360 bytes: a chunk closes every 3
  bag::BagWriter writer((dir / "a.bag").string(), options);
  const std::uint32_t imu = writer.addConnection("/imu_raw", ros::imuType());
  int written = 0;
  const auto writeOne = [&] {
    const Time t = kWriterT0 + written * kMs;
    writer.write(imu, t, ros::serializeImu(makeImu(t, written), written, "imu"));
    ++written;
  };
  while (writer.counts().chunks < 3) writeOne();
  const int flushed = written;
  writeOne();  // into the open chunk, which a killed process never writes
  fs::copy_file(dir / "a.bag.partial", dir / "killed.bag");  // what `kill -9` now would leave
  BagReader reader((dir / "killed.bag").string(), simTopics());
  ASSERT_FALSE(reader.warnings().empty());
  EXPECT_NE(reader.warnings()[0].find("not indexed"), std::string::npos) << reader.warnings()[0];
  int n = 0;
  while (auto m = reader.next()) {
    EXPECT_EQ(measurementTime(*m), kWriterT0 + n * kMs);
    ++n;
  }
  EXPECT_EQ(n, flushed) << "the messages of the complete chunks, not those of the open one";
}

TEST(BagWriter, AnExistingPathIsReplacedOnlyWithOverwriteAndOnlyWhenItIsABag) {
  TempDir dir;
  const fs::path bag = dir / "a.bag";
  writeTestBag(bag, 768 * 1024);
  test::writeText(dir / "notes.txt", "mine");
  fs::create_directories(dir / "folder.bag");
  bag::WriterOptions keep;
  test::expectIoError([&] { bag::BagWriter::checkOutput(bag.string(), keep); },
                      {bag.string(), "--out", "already exists", "--force"});
  bag::WriterOptions replace;
  replace.overwrite = true;
  test::expectIoError([&] { bag::BagWriter::checkOutput((dir / "notes.txt").string(), replace); },
                      {"notes.txt", "is not a ROS bag"});
  test::expectIoError([&] { bag::BagWriter::checkOutput((dir / "folder.bag").string(), replace); },
                      {"folder.bag", "folder"});
  test::expectIoError([&] { bag::BagWriter::checkOutput((dir / "missing" / "a.bag").string(), replace); },
                      {"missing", "does not exist"});
  test::writeText(dir / "b.bag.partial", "someone's file");
  test::expectIoError([&] { bag::BagWriter::checkOutput((dir / "b.bag").string(), replace); },
                      {"b.bag.partial", "not a bag an interrupted run left"});
  bag::BagWriter writer(bag.string(), replace);  // an earlier bag: replaced by finish()
  writer.addConnection("/imu_raw", ros::imuType());
  writer.finish();
  BagReader reader(bag.string(), simTopics());
  EXPECT_FALSE(reader.next().has_value()) << "the new, empty bag replaced the old one";
  std::ifstream notes(dir / "notes.txt");
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(notes), {}), "mine") << "a file not a bag is left alone";
}

}  // namespace
}  // namespace drover::io
