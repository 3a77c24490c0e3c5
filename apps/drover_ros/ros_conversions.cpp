#include "apps/drover_ros/ros_conversions.hpp"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <stdexcept>

#include "io/ros_messages.hpp"

namespace drover::ros_node {

::ros::Time toRosTime(Time t) {
  if (t < 0) throw std::invalid_argument("time " + std::to_string(t) + " ns is before the Unix epoch");
  ::ros::Time r;
  r.fromNSec(static_cast<std::uint64_t>(t));
  return r;
}

Time fromRosTime(const ::ros::Time& t) { return static_cast<Time>(t.toNSec()); }

io::ros::DecodedCloud toLidarScan(const sensor_msgs::PointCloud2& message) {
  const std::vector<std::uint8_t> bytes = wireBytes(message);
  return io::ros::decodePointCloud2(bytes.data(), bytes.size());
}

ImuSample toImuSample(const sensor_msgs::Imu& message) {
  const std::vector<std::uint8_t> bytes = wireBytes(message);
  return io::ros::decodeImu(bytes.data(), bytes.size());
}

CameraFrame toCameraFrame(const sensor_msgs::Image& message) {
  const std::vector<std::uint8_t> bytes = wireBytes(message);
  return io::ros::decodeImage(bytes.data(), bytes.size());
}

CameraFrame toCameraFrame(const sensor_msgs::CompressedImage& message) {
  const std::vector<std::uint8_t> bytes = wireBytes(message);
  return io::ros::decodeCompressedImage(bytes.data(), bytes.size());
}

geometry_msgs::Pose toPose(const Eigen::Isometry3d& T) {
  geometry_msgs::Pose p;
  p.position.x = T.translation().x();
  p.position.y = T.translation().y();
  p.position.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  p.orientation.x = q.x();
  p.orientation.y = q.y();
  p.orientation.z = q.z();
  p.orientation.w = q.w();
  return p;
}

geometry_msgs::TransformStamped toTransform(const Eigen::Isometry3d& T_parent_child, Time t, const std::string& parent,
                                            const std::string& child) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = toRosTime(t);
  m.header.frame_id = parent;
  m.child_frame_id = child;
  const geometry_msgs::Pose p = toPose(T_parent_child);
  m.transform.translation.x = p.position.x;
  m.transform.translation.y = p.position.y;
  m.transform.translation.z = p.position.z;
  m.transform.rotation = p.orientation;
  return m;
}

nav_msgs::Odometry toOdometry(const live::BodyPose& pose, const std::string& frame, const std::string& child) {
  nav_msgs::Odometry m;
  m.header.stamp = toRosTime(pose.t);
  m.header.frame_id = frame;
  m.child_frame_id = child;
  m.pose.pose = toPose(pose.T_world_body);
  if (pose.has_velocity) {
    const Eigen::Vector3d v_body = pose.T_world_body.linear().transpose() * pose.v_world;
    m.twist.twist.linear.x = v_body.x();
    m.twist.twist.linear.y = v_body.y();
    m.twist.twist.linear.z = v_body.z();
  }
  return m;
}

nav_msgs::Path toPath(const Trajectory& poses, Time stamp, const std::string& frame) {
  nav_msgs::Path path;
  path.header.stamp = toRosTime(stamp);
  path.header.frame_id = frame;
  path.poses.reserve(poses.size());
  for (const StampedPose& p : poses) {
    geometry_msgs::PoseStamped s;
    s.header.stamp = toRosTime(p.t);
    s.header.frame_id = frame;
    s.pose = toPose(p.T_world_body);
    path.poses.push_back(s);
  }
  return path;
}

sensor_msgs::PointCloud2 toPointCloud2(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& intensity,
                                       Time stamp, const std::string& frame) {
  if (!intensity.empty() && intensity.size() != points.size())
    throw std::invalid_argument("toPointCloud2: " + std::to_string(intensity.size()) + " intensities for " +
                                std::to_string(points.size()) + " points");
  sensor_msgs::PointCloud2 m;
  m.header.stamp = toRosTime(stamp);
  m.header.frame_id = frame;
  sensor_msgs::PointCloud2Modifier modifier(m);
  if (intensity.empty())
    modifier.setPointCloud2Fields(3, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                                  "z", 1, sensor_msgs::PointField::FLOAT32);
  else
    modifier.setPointCloud2Fields(4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32,
                                  "z", 1, sensor_msgs::PointField::FLOAT32, "intensity", 1,
                                  sensor_msgs::PointField::FLOAT32);
  modifier.resize(points.size());  // height 1, width n, dense
  sensor_msgs::PointCloud2Iterator<float> x(m, "x");
  for (std::size_t i = 0; i < points.size(); ++i, ++x) {
    x[0] = points[i].x();
    x[1] = points[i].y();
    x[2] = points[i].z();
  }
  if (!intensity.empty()) {
    sensor_msgs::PointCloud2Iterator<float> in(m, "intensity");
    for (std::size_t i = 0; i < points.size(); ++i, ++in) *in = intensity[i];
  }
  return m;
}

sensor_msgs::PointCloud2 toPointCloud2(const LidarScan& scan, const Eigen::Isometry3d& T_frame_lidar, Time stamp,
                                       const std::string& frame) {
  const Eigen::Isometry3f T = T_frame_lidar.cast<float>();
  std::vector<Eigen::Vector3f> points;
  std::vector<float> intensity;
  points.reserve(scan.points.size());
  intensity.reserve(scan.points.size());
  for (const LidarPoint& p : scan.points) {
    points.push_back(T * Eigen::Vector3f(p.x, p.y, p.z));
    intensity.push_back(p.intensity);
  }
  return toPointCloud2(points, intensity, stamp, frame);
}

visualization_msgs::MarkerArray loopMarkers(const live::LiveView& view, Time stamp, const std::string& frame) {
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  visualization_msgs::Marker lines, ends;
  for (visualization_msgs::Marker* m : {&lines, &ends}) {
    m->header.stamp = toRosTime(stamp);
    m->header.frame_id = frame;
    m->ns = m == &lines ? "loop_edges" : "loop_nodes";
    m->action = visualization_msgs::Marker::ADD;
    m->pose.orientation.w = 1;
    m->color.r = 0.9f;  // loop closures in yellow, as LIO-SAM shows them
    m->color.g = 0.9f;
    m->color.a = 1.0f;
  }
  lines.type = visualization_msgs::Marker::LINE_LIST;
  lines.scale.x = 0.1;  // [m] line width
  ends.type = visualization_msgs::Marker::SPHERE_LIST;
  ends.scale.x = ends.scale.y = ends.scale.z = 0.3;  // [m]
  for (const live::LoopLink& l : view.loops) {
    if (l.query >= view.keyframes.size() || l.candidate >= view.keyframes.size()) continue;
    for (std::size_t k : {l.candidate, l.query}) {
      const geometry_msgs::Pose p = toPose(view.keyframes[k].T_world_body);
      lines.points.push_back(p.position);
      ends.points.push_back(p.position);
    }
  }
  if (!lines.points.empty()) {
    array.markers.push_back(lines);
    array.markers.push_back(ends);
  }
  return array;
}

}  // namespace drover::ros_node
