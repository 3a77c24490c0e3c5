// The bag reader's ground truth: nav_msgs/Odometry on dataset.ground_truth_topic (a simulated bag's /ground_truth),
// on bags written by Drover's bag writer; bad ground truth is an IoError naming the bag, topic and message.
#include <gtest/gtest.h>

#include <string>

#include "io/bag_reader.hpp"
#include "io/bag_writer.hpp"
#include "io/config.hpp"
#include "io/ros_serialize.hpp"
#include "support/expect_io_error.hpp"
#include "support/temp_dir.hpp"
#include "support/units.hpp"

namespace drover::io {
namespace {

constexpr Time kT0 = Time{1'700'000'000} * kNanosPerSecond;
using ::drover::test::kMs;

ros::Odometry odometry(Time t, const std::string& child = "imu") {
  ros::Odometry o;
  o.t = t;
  o.frame_id = "world";
  o.child_frame_id = child;
  o.T_frame_child.translation() = Eigen::Vector3d(toSeconds(t - kT0), 0.0, 0.4);
  return o;
}

// A bag with IMU samples at 100 Hz and ground truth at the given stamps (and child frames) on /ground_truth.
std::string writeBag(const test::TempDir& dir, const std::vector<Time>& gt_times, const std::string& child = "imu",
                     const ros::MessageType& gt_type = ros::odometryType()) {
  const std::string path = (dir / "gt.bag").string();
  bag::BagWriter writer(path);
  const std::uint32_t imu = writer.addConnection("/imu_raw", ros::imuType());
  const std::uint32_t gt = writer.addConnection("/ground_truth", gt_type);
  for (int k = 0; k < 10; ++k) {
    ImuSample s;
    s.t = kT0 + k * 10 * kMs;
    s.acc_imu.z() = 9.81;
    writer.write(imu, s.t, ros::serializeImu(s, k, "imu"));
  }
  std::uint32_t seq = 0;
  for (Time t : gt_times) {
    ImuSample s;  // for a wrong type on the topic
    s.t = t;
    writer.write(gt, kT0 + 100 * kMs,
                 &gt_type == &ros::odometryType() ? ros::serializeOdometry(odometry(t, child), seq++)
                                                  : ros::serializeImu(s, seq++, "imu"));
  }
  writer.finish();
  return path;
}

DatasetOptions withGroundTruth(const std::string& topic = "/ground_truth") {
  DatasetOptions o;
  o.ground_truth_topic = topic;
  return o;
}

TEST(BagGroundTruth, OdometryOnTheConfiguredTopicIsTheGroundTruthOfItsChildFrame) {
  test::TempDir dir;
  const std::string path = writeBag(dir, {kT0, kT0 + 20 * kMs, kT0 + 40 * kMs}, "lidar");
  BagReader reader(path, withGroundTruth());
  const GroundTruth& gt = reader.groundTruth();
  EXPECT_EQ(gt.body_frame, "lidar");
  ASSERT_EQ(gt.poses.size(), 3u);
  EXPECT_EQ(gt.poses[2].t, kT0 + 40 * kMs);
  EXPECT_NEAR(gt.poses[2].T_world_body.translation().x(), 0.04, 1e-15);
  EXPECT_NE(reader.describe().find("ground truth /ground_truth (3 poses of the lidar)"), std::string::npos)
      << reader.describe();
}

TEST(BagGroundTruth, WithoutAGroundTruthTopicInTheConfigTheBagHasNone) {
  test::TempDir dir;
  BagReader reader(writeBag(dir, {kT0, kT0 + 20 * kMs}), DatasetOptions{});
  EXPECT_TRUE(reader.groundTruth().poses.empty());
}

TEST(BagGroundTruth, AConfiguredTopicMissingFromTheBagIsAWarningAndNoGroundTruth) {
  test::TempDir dir;
  BagReader reader(writeBag(dir, {kT0}), withGroundTruth("/gt"));
  EXPECT_TRUE(reader.groundTruth().poses.empty());
  EXPECT_NE(reader.describe().find("ground-truth topic /gt is not in the bag"), std::string::npos)
      << reader.describe();
}

TEST(BagGroundTruth, ARepeatedStampIsDroppedWithANoticeNamingTheMessage) {
  test::TempDir dir;
  BagReader reader(writeBag(dir, {kT0, kT0 + 20 * kMs, kT0 + 20 * kMs, kT0 + 40 * kMs}), withGroundTruth());
  EXPECT_EQ(reader.groundTruth().poses.size(), 3u);
  ASSERT_EQ(reader.drops().measurements, 1u);
  EXPECT_NE(reader.drops().notices[0].find("topic /ground_truth message 2"), std::string::npos)
      << reader.drops().notices[0];
}

TEST(BagGroundTruth, AnotherMessageTypeOnTheTopicIsAnErrorNamingBoth) {
  test::TempDir dir;
  const std::string path = writeBag(dir, {kT0}, "imu", ros::imuType());
  test::expectIoError([&] { BagReader(path, withGroundTruth()); },
                      {path, "topic /ground_truth", "sensor_msgs/Imu", "nav_msgs/Odometry"});
}

TEST(BagGroundTruth, AChildFrameOtherThanImuOrLidarIsAnErrorNamingTheMessage) {
  test::TempDir dir;
  const std::string path = writeBag(dir, {kT0, kT0 + 20 * kMs}, "base_link");
  test::expectIoError([&] { BagReader(path, withGroundTruth()); },
                      {path, "topic /ground_truth message 0", "'base_link'", "neither imu nor lidar"});
}

TEST(BagGroundTruth, ThePlatformConfigNamesTheTopicAsDatasetGroundTruthTopic) {
  test::TempDir dir;
  test::writeText(dir / "p.yaml", "dataset:\n  ground_truth_topic: /gt_odom\n");
  EXPECT_EQ(loadDatasetOptions((dir / "p.yaml").string()).ground_truth_topic, "/gt_odom");
  EXPECT_EQ(loadDatasetOptions((dir / "p.yaml").string()).lidar_topic, "/points_raw") << "others keep defaults";
  EXPECT_EQ(DatasetOptions{}.ground_truth_topic, "") << "none unless configured";
}

}  // namespace
}  // namespace drover::io
