#pragma once
// drover_ros: the live Drover as a ROS1 node (LIO-SAM's and LVI-SAM's interface). Sensor topics come from the
// platform config (`~config`, the file `drover run --config` takes); each sensor has its own callback queue and
// thread, so every stream reaches pipeline::System in its own order and a slow image decode never holds the IMU.
//
// Publishes (all under the node's private namespace):
//   odometry/imu    nav_msgs/Odometry at the IMU rate: the IMU's pose, propagated from the LIS's newest fused state
//   odometry/lidar  nav_msgs/Odometry per processed sweep, the body at the sweep's start
//   path            nav_msgs/Path of the keyframes (loop corrections included), every ~path_period s
//   cloud           sensor_msgs/PointCloud2: each processed sweep as the LIS matched it (deskewed to its start,
//                   downsampled), in the odom frame
//   map             sensor_msgs/PointCloud2 (latched): the keyframes' deskewed clouds in the map frame, voxel-
//                   downsampled (~map_leaf), every ~map_period s while someone listens
//   loops           visualization_msgs/MarkerArray: a line per accepted loop closure
//   tf              map -> odom (identity, see below), odom -> base_link (the odometry), and static base_link ->
//                   lidar / camera from the platform's extrinsics
// Frames: base_link is the body (the IMU; the lidar without one). Drover's LIS applies a loop correction to its own
// state (LIO-SAM's correctPoses), so its odometry is already the map-frame estimate and jumps when a loop closes;
// map -> odom is therefore the identity, as in LIO-SAM (a separate drift-free odom chain would need an odometry
// that never sees the loops, which Drover does not keep).
// Services (std_srvs/Trigger): save (drover run's run folder into ~save_dir), reset (a fresh map and trajectory).
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "apps/drover_ros/live_session.hpp"

namespace drover::ros_node {

struct NodeParams {
  std::string config;                                           // ~config: platform YAML (required)
  std::string map_frame = "map", odom_frame = "odom", base_frame = "base_link";
  std::string lidar_frame = "lidar", camera_frame = "camera";   // static tf children of base_link
  bool publish_tf = true;
  double map_period = 5.0;   // [s] between map publications (wall time)
  double map_leaf = 0.4;     // [m] voxel leaf of the published map
  double path_period = 1.0;  // [s] between path and loop-marker publications (wall time)
  std::string save_dir;      // ~save_dir: where ~save and ~save_on_exit write the run folder
  bool save_on_exit = false;
  live::LiveOptions live;    // ~use_camera, ~use_loop, ~sweep_queue, ~working_dir
  // Reads the private parameters; throws std::invalid_argument naming a bad one.
  static NodeParams read(const ::ros::NodeHandle& pnh);
};

class DroverNode {
 public:
  // Subscribes and starts the System. Throws io::IoError / std::invalid_argument for a bad config or parameter.
  DroverNode(::ros::NodeHandle nh, ::ros::NodeHandle pnh);
  ~DroverNode();
  // Unsubscribes, lets the System finish what is queued (its last outputs are still published) and, with
  // ~save_on_exit, saves. Returns false when that save failed. Idempotent.
  bool finish(const std::string& why);

 private:
  void onCloud(const sensor_msgs::PointCloud2::ConstPtr& message);
  void onImu(const sensor_msgs::Imu::ConstPtr& message);
  void onImage(const sensor_msgs::Image::ConstPtr& message);
  void onCompressedImage(const sensor_msgs::CompressedImage::ConstPtr& message);
  template <class Message>
  void onAnyImage(const Message& message);
  void onImuOdometry(const live::BodyPose& pose);
  void onSweep(const live::SweepResult& sweep);
  void onDeskewedSweep(Time t, const Eigen::Isometry3d& T_world_lidar, const std::vector<Eigen::Vector3f>& points_lidar);
  void publishView(bool with_map);
  bool onSave(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  bool onReset(std_srvs::Trigger::Request& request, std_srvs::Trigger::Response& response);
  void clearShown();
  void subscribe();
  void publishStatic();
  std::string record(const std::string& topic, const ::ros::Time& stamp) const;

  ::ros::NodeHandle nh_, pnh_;
  NodeParams params_;
  std::unique_ptr<live::LiveSession> session_;
  // One queue and spinner thread per sensor: each stream stays in order, none waits on another.
  ::ros::CallbackQueue imu_queue_, lidar_queue_, camera_queue_;
  std::unique_ptr<::ros::AsyncSpinner> imu_spinner_, lidar_spinner_, camera_spinner_;
  ::ros::Subscriber cloud_sub_, imu_sub_, image_sub_;
  ::ros::Publisher imu_odom_pub_, lidar_odom_pub_, path_pub_, cloud_pub_, map_pub_, loops_pub_;
  ::ros::ServiceServer save_srv_, reset_srv_;
  ::ros::WallTimer path_timer_, map_timer_;
  tf2_ros::TransformBroadcaster tf_;
  tf2_ros::StaticTransformBroadcaster static_tf_;

  std::mutex latest_mutex_;
  std::optional<live::BodyPose> latest_;  // the newest sweep pose, appended to the keyframe path
  std::atomic<bool> finished_{false};
};

}  // namespace drover::ros_node
