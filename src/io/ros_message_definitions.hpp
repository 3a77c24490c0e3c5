#pragma once
// The ROS1 message types Drover writes to bags, each with its md5sum and full definition text (the message and,
// after "====...\nMSG: pkg/Type" separators, every type it uses), as roscpp and rosbag put them in a connection
// header. Readers that have no compiled message classes (python rosbag, rosbag_storage's MessageInstance,
// foxglove) build the decoder from that text, and rosbag checks it against the md5sum. The texts are generated
// from Debian's ROS headers by tools/ros_message_definitions.py (ROS Noetic common_msgs 1.13.1).
#include <string_view>

namespace drover::io::ros {

struct MessageType {
  std::string_view name;        // "sensor_msgs/Imu"
  std::string_view md5sum;      // 32 hex digits
  std::string_view definition;  // full text, ends with '\n'
};

const MessageType& pointCloud2Type();  // sensor_msgs/PointCloud2
const MessageType& imuType();          // sensor_msgs/Imu
const MessageType& imageType();        // sensor_msgs/Image
const MessageType& odometryType();     // nav_msgs/Odometry

}  // namespace drover::io::ros
