// ROS1 messages <-> Drover types (apps/drover_ros/ros_conversions.hpp): each expected value is written out here
// from the message built in the test, independently of the decoder.
#include <gtest/gtest.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "apps/drover_ros/ros_conversions.hpp"
#include "io/ros_messages.hpp"

namespace drover::ros_node {
namespace {

constexpr Time kStamp = 1'700'000'000'123'456'789;  // [ns]

// A Velodyne driver's cloud (velodyne_pointcloud's XYZIRT): float32 x y z intensity, uint16 ring, float32 time
// [s] relative to the header stamp, 22 bytes a point with padding as the driver packs it.
sensor_msgs::PointCloud2 velodyneCloud(const std::vector<LidarPoint>& points, const std::vector<float>& times) {
  sensor_msgs::PointCloud2 m;
  m.header.stamp = toRosTime(kStamp);
  m.header.frame_id = "velodyne";
  sensor_msgs::PointCloud2Modifier modifier(m);
  modifier.setPointCloud2Fields(6, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                                "z", 1, sensor_msgs::PointField::FLOAT32, "intensity", 1,
                                sensor_msgs::PointField::FLOAT32, "ring", 1, sensor_msgs::PointField::UINT16, "time", 1,
                                sensor_msgs::PointField::FLOAT32);
  modifier.resize(points.size());
  sensor_msgs::PointCloud2Iterator<float> x(m, "x"), intensity(m, "intensity"), time(m, "time");
  sensor_msgs::PointCloud2Iterator<std::uint16_t> ring(m, "ring");
  for (std::size_t i = 0; i < points.size(); ++i, ++x, ++intensity, ++time, ++ring) {
    x[0] = points[i].x;
    x[1] = points[i].y;
    x[2] = points[i].z;
    *intensity = points[i].intensity;
    *ring = points[i].ring;
    *time = times[i];
  }
  return m;
}

LidarPoint point(float x, float y, float z, float intensity, std::uint16_t ring) {
  LidarPoint p;
  p.x = x, p.y = y, p.z = z, p.intensity = intensity, p.ring = ring;
  return p;
}

TEST(RosConversions, VelodyneCloudBecomesAScanWithRingsAndPerPointTimesFromTheStamp) {
  const std::vector<LidarPoint> in{point(1, 2, 3, 10, 0), point(-4, 5, 0.5f, 200, 15), point(7, -8, -1, 0, 7)};
  const io::ros::DecodedCloud cloud = toLidarScan(velodyneCloud(in, {0.0f, 0.05f, 0.099f}));
  const LidarScan& s = cloud.scan;
  EXPECT_EQ(cloud.stamp, kStamp);
  EXPECT_EQ(s.t, kStamp);  // the stamp marks the sweep start: kept
  EXPECT_NEAR(static_cast<double>(s.t_end - kStamp), 0.099e9, 1e3);
  ASSERT_TRUE(s.has_ring);
  ASSERT_TRUE(s.has_time);
  ASSERT_EQ(s.points.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(s.points[i].x, in[i].x);
    EXPECT_FLOAT_EQ(s.points[i].y, in[i].y);
    EXPECT_FLOAT_EQ(s.points[i].z, in[i].z);
    EXPECT_FLOAT_EQ(s.points[i].intensity, in[i].intensity);
    EXPECT_EQ(s.points[i].ring, in[i].ring);
  }
  EXPECT_NEAR(s.points[1].time_offset, 0.05f, 1e-6f);
  EXPECT_NEAR(s.points[2].time_offset, 0.099f, 1e-6f);
}

TEST(RosConversions, CloudStampedAtTheSweepEndStartsAtItsEarliestPoint) {
  // Drivers that stamp the sweep's end give negative times: the scan starts 0.1 s before the stamp.
  const io::ros::DecodedCloud cloud =
      toLidarScan(velodyneCloud({point(1, 0, 0, 1, 0), point(0, 1, 0, 1, 1)}, {-0.1f, 0.0f}));
  EXPECT_NEAR(static_cast<double>(kStamp - cloud.scan.t), 0.1e9, 1e3);
  EXPECT_EQ(cloud.scan.t_end, kStamp);
  EXPECT_NEAR(cloud.scan.points[0].time_offset, 0.0f, 1e-6f);
  EXPECT_NEAR(cloud.scan.points[1].time_offset, 0.1f, 1e-6f);
}

TEST(RosConversions, CloudWithNanPointsDropsAndCountsThem) {
  const io::ros::DecodedCloud cloud =
      toLidarScan(velodyneCloud({point(1, 0, 0, 1, 0), point(NAN, 1, 0, 1, 1), point(0, 0, 2, 1, 2)}, {0, 0, 0}));
  EXPECT_EQ(cloud.scan.points.size(), 2u);
  EXPECT_EQ(cloud.dropped_nonfinite, 1u);
}

TEST(RosConversions, CloudWithAnUnreadableFieldIsAnErrorNamingTheField) {
  sensor_msgs::PointCloud2 m = velodyneCloud({point(1, 0, 0, 1, 0)}, {0});
  m.fields[0].datatype = sensor_msgs::PointField::INT8;  // x as int8
  try {
    toLidarScan(m);
    FAIL() << "expected MessageError";
  } catch (const io::ros::MessageError& e) {
    EXPECT_NE(std::string(e.what()).find("'x'"), std::string::npos) << e.what();
  }
}

TEST(RosConversions, ImuBecomesASampleInTheImuFrameWithItsOrientationWhenGiven) {
  sensor_msgs::Imu m;
  m.header.stamp = toRosTime(kStamp);
  m.angular_velocity.x = 0.1, m.angular_velocity.y = -0.2, m.angular_velocity.z = 0.3;
  m.linear_acceleration.x = 0.5, m.linear_acceleration.y = 0.0, m.linear_acceleration.z = 9.81;
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  m.orientation.x = q.x(), m.orientation.y = q.y(), m.orientation.z = q.z(), m.orientation.w = q.w();
  const ImuSample s = toImuSample(m);
  EXPECT_EQ(s.t, kStamp);
  EXPECT_TRUE(s.omega_imu.isApprox(Eigen::Vector3d(0.1, -0.2, 0.3)));
  EXPECT_TRUE(s.acc_imu.isApprox(Eigen::Vector3d(0.5, 0.0, 9.81)));
  ASSERT_TRUE(s.q_world_imu.has_value());
  EXPECT_NEAR(s.q_world_imu->angularDistance(q), 0.0, 1e-9);
  m.orientation_covariance[0] = -1;  // REP 145: no orientation estimate
  EXPECT_FALSE(toImuSample(m).q_world_imu.has_value());
}

TEST(RosConversions, MonoImageWithRowPaddingBecomesATightlyPackedFrame) {
  sensor_msgs::Image m;
  m.header.stamp = toRosTime(kStamp);
  m.width = 3, m.height = 2, m.encoding = "mono8", m.step = 4;  // one byte of padding per row
  m.data = {1, 2, 3, 99, 4, 5, 6, 99};
  const CameraFrame f = toCameraFrame(m);
  EXPECT_EQ(f.t, kStamp);
  EXPECT_EQ(f.image.width, 3);
  EXPECT_EQ(f.image.channels, 1);
  EXPECT_EQ(f.image.data, (std::vector<std::uint8_t>{1, 2, 3, 4, 5, 6}));
}

TEST(RosConversions, CompressedPngDecodesToTheSamePixels) {
  cv::Mat grey(4, 5, CV_8UC1);
  for (int i = 0; i < grey.rows * grey.cols; ++i) grey.data[i] = static_cast<std::uint8_t>(i * 11);
  sensor_msgs::CompressedImage m;
  m.header.stamp = toRosTime(kStamp);
  m.format = "mono8; png compressed ";
  cv::imencode(".png", grey, m.data);
  const CameraFrame f = toCameraFrame(m);
  EXPECT_EQ(f.t, kStamp);
  ASSERT_EQ(f.image.width * f.image.height, 20);
  EXPECT_EQ(f.image.data, std::vector<std::uint8_t>(grey.data, grey.data + 20));
}

TEST(RosConversions, OdometryCarriesThePoseAndTheVelocityInTheBodyFrame) {
  live::BodyPose p;
  p.t = kStamp;
  // Body yawed 90 deg (x forward = world y) at (1, 2, 3), moving along world y at 2 m/s: 2 m/s forward in the body.
  p.T_world_body = Eigen::Translation3d(1, 2, 3) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  p.v_world = Eigen::Vector3d(0, 2, 0);
  p.has_velocity = true;
  const nav_msgs::Odometry m = toOdometry(p, "odom", "base_link");
  EXPECT_EQ(fromRosTime(m.header.stamp), kStamp);
  EXPECT_EQ(m.header.frame_id, "odom");
  EXPECT_EQ(m.child_frame_id, "base_link");
  EXPECT_DOUBLE_EQ(m.pose.pose.position.x, 1);
  EXPECT_DOUBLE_EQ(m.pose.pose.position.y, 2);
  EXPECT_DOUBLE_EQ(m.pose.pose.position.z, 3);
  EXPECT_NEAR(m.pose.pose.orientation.z, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(m.pose.pose.orientation.w, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(m.twist.twist.linear.x, 2.0, 1e-12);
  EXPECT_NEAR(m.twist.twist.linear.y, 0.0, 1e-12);
  p.has_velocity = false;
  EXPECT_EQ(toOdometry(p, "odom", "base_link").twist.twist.linear.x, 0.0);  // unknown: zero, not a stale value
}

TEST(RosConversions, PublishedSweepIsMovedIntoTheTargetFrameAndReadsBackThroughTheDecoder) {
  LidarScan scan;
  scan.points = {point(1, 0, 0, 5, 0), point(0, 2, 0, 6, 0)};
  const Eigen::Isometry3d T(Eigen::Translation3d(10, 0, 0) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const io::ros::DecodedCloud back = toLidarScan(toPointCloud2(scan, T, kStamp, "odom"));
  ASSERT_EQ(back.scan.points.size(), 2u);
  EXPECT_NEAR(back.scan.points[0].x, 10, 1e-5);  // (1, 0, 0) turned to (0, 1, 0), then moved by 10 m along x
  EXPECT_NEAR(back.scan.points[0].y, 1, 1e-5);
  EXPECT_NEAR(back.scan.points[1].x, 8, 1e-5);
  EXPECT_NEAR(back.scan.points[1].y, 0, 1e-5);
  EXPECT_FLOAT_EQ(back.scan.points[1].intensity, 6);
  EXPECT_EQ(back.stamp, kStamp);
}

TEST(RosConversions, LoopMarkersJoinTheTwoKeyframesOfEachLoopAndSkipUnknownOnes) {
  live::LiveView view;
  for (int i = 0; i < 3; ++i)
    view.keyframes.push_back({kStamp + i, Eigen::Isometry3d(Eigen::Translation3d(i, 2.0 * i, 0))});
  view.loops = {{2, 0, kStamp + 2, kStamp}, {7, 1, 0, 0}};  // the second names a keyframe that does not exist
  const visualization_msgs::MarkerArray a = loopMarkers(view, kStamp, "map");
  ASSERT_EQ(a.markers.size(), 3u);  // DELETEALL, the lines, the ends
  EXPECT_EQ(a.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const visualization_msgs::Marker& lines = a.markers[1];
  ASSERT_EQ(lines.points.size(), 2u);
  EXPECT_DOUBLE_EQ(lines.points[0].x, 0);  // candidate 0
  EXPECT_DOUBLE_EQ(lines.points[1].x, 2);  // query 2
  EXPECT_DOUBLE_EQ(lines.points[1].y, 4);
}

TEST(RosConversions, TimesBeforeTheEpochAreRejected) {
  EXPECT_THROW(toRosTime(-1), std::invalid_argument);
  EXPECT_EQ(fromRosTime(toRosTime(kStamp)), kStamp);
}

}  // namespace
}  // namespace drover::ros_node
