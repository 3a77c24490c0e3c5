#pragma once
// ROS1 messages <-> Drover types, for the node (C++17: see live_session.hpp).
//
// Sensor messages in are decoded exactly as `drover run --format bag` decodes them: the message is serialised to
// its ROS1 wire bytes (what a bag holds) and handed to Drover's own decoders (io/ros_pointcloud.hpp for any
// PointCloud2 field layout and per-point time field, io/ros_messages.hpp for Imu, Image and CompressedImage), so a
// live sweep and the same sweep read from a bag are the same LidarScan. The copy costs about a millisecond for a
// 30k-point sweep.
#include <Eigen/Geometry>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/serialization.h>
#include <ros/time.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <cstdint>
#include <string>
#include <vector>

#include "apps/drover_ros/live_session.hpp"
#include "io/ros_pointcloud.hpp"
#include "types/camera.hpp"
#include "types/imu.hpp"
#include "types/lidar.hpp"

namespace drover::ros_node {

// [ns] since the Unix epoch <-> ros::Time. Throws std::invalid_argument for a time before the epoch.
::ros::Time toRosTime(Time t);
Time fromRosTime(const ::ros::Time& t);

// The message's ROS1 wire bytes.
template <typename Message>
std::vector<std::uint8_t> wireBytes(const Message& message) {
  const std::uint32_t n = ::ros::serialization::serializationLength(message);
  std::vector<std::uint8_t> bytes(n);
  ::ros::serialization::OStream stream(bytes.data(), n);
  ::ros::serialization::serialize(stream, message);
  return bytes;
}

// Throw io::ros::MessageError saying what is wrong (an unsupported field layout or encoding, a cut-off payload).
io::ros::DecodedCloud toLidarScan(const sensor_msgs::PointCloud2& message);
ImuSample toImuSample(const sensor_msgs::Imu& message);
CameraFrame toCameraFrame(const sensor_msgs::Image& message);
CameraFrame toCameraFrame(const sensor_msgs::CompressedImage& message);

geometry_msgs::Pose toPose(const Eigen::Isometry3d& T);
geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T_parent_child, Time t, const std::string& parent,
                                            const std::string& child);
// nav_msgs/Odometry of the body in `frame`: the pose T_frame_body, the twist in the body frame (nav_msgs'
// convention: twist in child_frame_id), zero when the velocity is unknown.
nav_msgs::Odometry toOdometry(const live::BodyPose& pose, const std::string& frame, const std::string& child);
nav_msgs::Path toPath(const Trajectory& poses, Time stamp, const std::string& frame);

// An unorganised cloud with float32 x, y, z (and intensity when given, one per point) in `frame`.
sensor_msgs::PointCloud2 toPointCloud2(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& intensity,
                                       Time stamp, const std::string& frame);
// The sweep's points moved by T_frame_lidar into `frame`, with their intensity.
sensor_msgs::PointCloud2 toPointCloud2(const LidarScan& scan, const Eigen::Isometry3d& T_frame_lidar, Time stamp,
                                       const std::string& frame);

// Loop closures for RViz: one line per accepted loop between its keyframes' positions, and a sphere at each end.
// Replaces the whole array each time (a DELETEALL marker first).
visualization_msgs::MarkerArray loopMarkers(const live::LiveView& view, Time stamp, const std::string& frame);

}  // namespace drover::ros_node
