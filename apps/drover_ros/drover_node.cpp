#include "apps/drover_ros/drover_node.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "apps/drover_ros/ros_conversions.hpp"
#include "io/ros_messages.hpp"

namespace drover::ros_node {
namespace {

constexpr std::uint32_t kImuQueue = 2000;      // [messages] ~10 s at 200 Hz: the IMU is never dropped by ROS
constexpr std::uint32_t kSensorQueue = 5;      // [messages] sweeps and images (the System bounds its own queues)

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

double positive(const ::ros::NodeHandle& pnh, const std::string& name, double fallback) {
  double v = fallback;
  pnh.param(name, v, fallback);
  if (!std::isfinite(v) || v <= 0)
    throw std::invalid_argument("~" + name + " must be a number > 0, got " + std::to_string(v));
  return v;
}

}  // namespace

NodeParams NodeParams::read(const ::ros::NodeHandle& pnh) {
  NodeParams p;
  if (!pnh.getParam("config", p.config) || p.config.empty())
    throw std::invalid_argument("~config is not set: give the platform config (as drover run --config), e.g. "
                                "_config:=config/m2dgr.yaml");
  pnh.param("map_frame", p.map_frame, p.map_frame);
  pnh.param("odom_frame", p.odom_frame, p.odom_frame);
  pnh.param("base_frame", p.base_frame, p.base_frame);
  pnh.param("lidar_frame", p.lidar_frame, p.lidar_frame);
  pnh.param("camera_frame", p.camera_frame, p.camera_frame);
  pnh.param("publish_tf", p.publish_tf, p.publish_tf);
  p.map_period = positive(pnh, "map_period", p.map_period);
  p.map_leaf = positive(pnh, "map_leaf", p.map_leaf);
  p.path_period = positive(pnh, "path_period", p.path_period);
  pnh.param("save_dir", p.save_dir, p.save_dir);
  pnh.param("save_on_exit", p.save_on_exit, p.save_on_exit);
  if (p.save_on_exit && p.save_dir.empty()) throw std::invalid_argument("~save_on_exit is set but ~save_dir is not");
  p.live.config = p.config;
  pnh.param("use_camera", p.live.use_camera, p.live.use_camera);
  pnh.param("use_loop", p.live.use_loop, p.live.use_loop);
  pnh.param("working_dir", p.live.working_dir, p.live.working_dir);
  if (std::error_code ec; !p.live.working_dir.empty() && !std::filesystem::is_directory(p.live.working_dir, ec))
    throw std::invalid_argument("~working_dir is not a folder: " + p.live.working_dir);
  int queue = static_cast<int>(p.live.sweep_queue);
  pnh.param("sweep_queue", queue, queue);
  if (queue < 1 || queue > 100) throw std::invalid_argument("~sweep_queue must be 1 ... 100, got " + std::to_string(queue));
  p.live.sweep_queue = static_cast<std::size_t>(queue);
  return p;
}

DroverNode::DroverNode(::ros::NodeHandle nh, ::ros::NodeHandle pnh)
    : nh_(std::move(nh)), pnh_(std::move(pnh)), params_(NodeParams::read(pnh_)) {
  imu_odom_pub_ = pnh_.advertise<nav_msgs::Odometry>("odometry/imu", 200);
  lidar_odom_pub_ = pnh_.advertise<nav_msgs::Odometry>("odometry/lidar", 20);
  path_pub_ = pnh_.advertise<nav_msgs::Path>("path", 1, true);
  cloud_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("cloud", 2);
  map_pub_ = pnh_.advertise<sensor_msgs::PointCloud2>("map", 1, true);
  loops_pub_ = pnh_.advertise<visualization_msgs::MarkerArray>("loops", 1, true);
  live::LiveCallbacks callbacks;
  callbacks.imu_odometry = [this](const live::BodyPose& p) { onImuOdometry(p); };
  callbacks.sweep = [this](const live::SweepResult& s) { onSweep(s); };
  callbacks.deskewed_sweep = [this](Time t, const Eigen::Isometry3d& T, const std::vector<Eigen::Vector3f>& p) {
    onDeskewedSweep(t, T, p);
  };
  callbacks.loop = [](const live::LoopLink& l) {
    ROS_INFO("drover: loop closed between keyframes %zu and %zu (%.3f s and %.3f s)", l.candidate, l.query,
             toSeconds(l.t_candidate), toSeconds(l.t_query));
  };
  callbacks.warning = [](const std::string& w) { ROS_WARN_STREAM("drover: " << w); };
  callbacks.restarted = [this](const std::string&) { clearShown(); };  // e.g. `rosbag play --loop` started over
  session_ = std::make_unique<live::LiveSession>(params_.live, callbacks);
  publishStatic();
  subscribe();
  path_timer_ = nh_.createWallTimer(::ros::WallDuration(params_.path_period), [this](const ::ros::WallTimerEvent&) {
    publishView(false);
  });
  map_timer_ = nh_.createWallTimer(::ros::WallDuration(params_.map_period), [this](const ::ros::WallTimerEvent&) {
    publishView(true);
  });
  // Last: a client that sees the services knows the node is subscribed.
  save_srv_ = pnh_.advertiseService("save", &DroverNode::onSave, this);
  reset_srv_ = pnh_.advertiseService("reset", &DroverNode::onReset, this);
}

DroverNode::~DroverNode() { finish("node destroyed"); }

void DroverNode::subscribe() {
  const io::DatasetOptions& p = session_->platform();
  const auto on = [](::ros::CallbackQueue& queue, std::unique_ptr<::ros::AsyncSpinner>& spinner) {
    ::ros::NodeHandle h;
    h.setCallbackQueue(&queue);
    spinner = std::make_unique<::ros::AsyncSpinner>(1, &queue);
    spinner->start();
    return h;
  };
  const ::ros::TransportHints fast = ::ros::TransportHints().tcpNoDelay();
  std::string topics = "lidar " + p.lidar_topic;
  cloud_sub_ = on(lidar_queue_, lidar_spinner_).subscribe(p.lidar_topic, kSensorQueue, &DroverNode::onCloud, this, fast);
  if (p.load_imu) {
    imu_sub_ = on(imu_queue_, imu_spinner_).subscribe(p.imu_topic, kImuQueue, &DroverNode::onImu, this, fast);
    topics += ", IMU " + p.imu_topic;
  }
  if (session_->visRuns()) {
    ::ros::NodeHandle h = on(camera_queue_, camera_spinner_);
    // image_transport's convention: a topic ending in /compressed carries sensor_msgs/CompressedImage.
    image_sub_ = endsWith(p.image_topic, "/compressed")
                     ? h.subscribe(p.image_topic, kSensorQueue, &DroverNode::onCompressedImage, this, fast)
                     : h.subscribe(p.image_topic, kSensorQueue, &DroverNode::onImage, this, fast);
    topics += ", camera " + p.image_topic;
  }
  ROS_INFO_STREAM("drover: " << params_.config << ": subscribed to " << topics << "; body frame "
                             << session_->bodyFrame()
                             << (session_->visRuns() ? ", VIS on with " + session_->visDetector() : ", VIS off"));
}

void DroverNode::publishStatic() {
  if (!params_.publish_tf) return;
  const Calibration& c = session_->platform().calibration;
  const bool imu_body = session_->bodyFrame() == "imu";
  std::vector<geometry_msgs::TransformStamped> statics;
  const Time now = fromRosTime(::ros::Time::now());
  statics.push_back(toTransform(Eigen::Isometry3d::Identity(), now, params_.map_frame, params_.odom_frame));
  statics.push_back(toTransform(imu_body ? c.T_imu_lidar : Eigen::Isometry3d::Identity(), now, params_.base_frame,
                                params_.lidar_frame));
  if (session_->visRuns())
    statics.push_back(toTransform(imu_body ? c.T_imu_cam : c.T_imu_lidar.inverse() * c.T_imu_cam, now,
                                  params_.base_frame, params_.camera_frame));
  static_tf_.sendTransform(statics);
}

std::string DroverNode::record(const std::string& topic, const ::ros::Time& stamp) const {
  return "topic " + topic + " message stamped " + std::to_string(stamp.toSec()) + " s";
}

void DroverNode::onCloud(const sensor_msgs::PointCloud2::ConstPtr& message) {
  try {
    io::ros::DecodedCloud cloud = toLidarScan(*message);
    session_->pushSweep(std::move(cloud.scan));
  } catch (const std::exception& e) {  // MessageError: a layout or payload the decoder cannot read
    session_->dropped(record(session_->platform().lidar_topic, message->header.stamp) + ": dropped: " + e.what());
  }
}

void DroverNode::onImu(const sensor_msgs::Imu::ConstPtr& message) {
  try {
    const ImuSample s = toImuSample(*message);
    // As the bag reader: a glitch of the IMU or its driver is dropped with a warning, not fed to the filter.
    if (!s.omega_imu.allFinite() || !s.acc_imu.allFinite())
      throw std::invalid_argument("angular velocity or linear acceleration is not finite");
    session_->pushImu(s);
  } catch (const std::exception& e) {
    session_->dropped(record(session_->platform().imu_topic, message->header.stamp) + ": dropped: " + e.what());
  }
}

// Image and CompressedImage alike: decoded (a bad one is dropped with a warning naming the message), then pushed.
template <class Message>
void DroverNode::onAnyImage(const Message& message) {
  const std::string where = record(session_->platform().image_topic, message.header.stamp);
  try {
    CameraFrame f = toCameraFrame(message);
    f.source = where;
    session_->pushFrame(std::move(f));
  } catch (const std::exception& e) {
    session_->dropped(where + ": dropped: " + e.what());
  }
}

void DroverNode::onImage(const sensor_msgs::Image::ConstPtr& message) { onAnyImage(*message); }

void DroverNode::onCompressedImage(const sensor_msgs::CompressedImage::ConstPtr& message) { onAnyImage(*message); }

void DroverNode::onImuOdometry(const live::BodyPose& pose) {
  imu_odom_pub_.publish(toOdometry(pose, params_.odom_frame, params_.base_frame));
  if (params_.publish_tf)
    tf_.sendTransform(toTransform(pose.T_world_body, pose.t, params_.odom_frame, params_.base_frame));
}

void DroverNode::onSweep(const live::SweepResult& sweep) {
  if (!sweep.warning.empty()) ROS_WARN("drover: sweep at %.3f s: %s", toSeconds(sweep.pose.t), sweep.warning.c_str());
  if (!sweep.note.empty()) ROS_INFO("drover: sweep at %.3f s: %s", toSeconds(sweep.pose.t), sweep.note.c_str());
  lidar_odom_pub_.publish(toOdometry(sweep.pose, params_.odom_frame, params_.base_frame));
  {
    std::lock_guard<std::mutex> lock(latest_mutex_);
    latest_ = sweep.pose;
  }
  // Without the IMU there is no IMU-rate odometry: the sweep poses carry odom -> base_link.
  if (params_.publish_tf && session_->bodyFrame() != "imu")
    tf_.sendTransform(toTransform(sweep.pose.T_world_body, sweep.pose.t, params_.odom_frame, params_.base_frame));
}

// The sweep as the LIS matched it (deskewed to its start, downsampled), in the odometry frame: only while someone
// listens.
void DroverNode::onDeskewedSweep(Time t, const Eigen::Isometry3d& T_world_lidar,
                                 const std::vector<Eigen::Vector3f>& points_lidar) {
  if (cloud_pub_.getNumSubscribers() == 0) return;
  const Eigen::Isometry3f T = T_world_lidar.cast<float>();
  std::vector<Eigen::Vector3f> world;
  world.reserve(points_lidar.size());
  for (const Eigen::Vector3f& p : points_lidar) world.push_back(T * p);
  cloud_pub_.publish(toPointCloud2(world, {}, t, params_.odom_frame));
}

void DroverNode::publishView(bool with_map) {
  if (finished_) return;
  const bool map_wanted = with_map && map_pub_.getNumSubscribers() > 0;
  const live::LiveView view = session_->view(map_wanted ? static_cast<float>(params_.map_leaf) : 0.0f);
  Trajectory path = view.keyframes;
  {
    std::lock_guard<std::mutex> lock(latest_mutex_);
    if (latest_ && (path.empty() || latest_->t > path.back().t)) path.push_back({latest_->t, latest_->T_world_body});
  }
  const Time stamp = path.empty() ? fromRosTime(::ros::Time::now()) : path.back().t;
  path_pub_.publish(toPath(path, stamp, params_.map_frame));
  loops_pub_.publish(loopMarkers(view, stamp, params_.map_frame));
  if (map_wanted) map_pub_.publish(toPointCloud2(view.map, {}, stamp, params_.map_frame));
}

bool DroverNode::onSave(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  if (params_.save_dir.empty()) {
    response.success = false;
    response.message = "~save_dir is not set";
    return true;
  }
  try {
    response.message = session_->save(params_.save_dir, "saved by the ~save service while running");
    response.success = true;
    ROS_INFO_STREAM("drover: " << response.message);
  } catch (const std::exception& e) {
    response.success = false;
    response.message = e.what();
    ROS_ERROR_STREAM("drover: save failed: " << e.what());
  }
  return true;
}

// After a reset: the newest pose goes, and the (now empty) path is published.
void DroverNode::clearShown() {
  {
    std::lock_guard<std::mutex> lock(latest_mutex_);
    latest_.reset();
  }
  publishView(false);
}

bool DroverNode::onReset(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
  const std::string before = session_->summary();
  session_->reset();
  clearShown();
  response.success = true;
  response.message = "reset: a fresh map and trajectory (before: " + before + ")";
  ROS_INFO_STREAM("drover: " << response.message);
  return true;
}

bool DroverNode::finish(const std::string& why) {
  if (finished_.exchange(true)) return true;
  for (::ros::Subscriber* s : {&cloud_sub_, &imu_sub_, &image_sub_}) s->shutdown();
  for (auto* spinner : {&lidar_spinner_, &imu_spinner_, &camera_spinner_})
    if (*spinner) (*spinner)->stop();
  path_timer_.stop();
  map_timer_.stop();
  session_->shutdown();  // the queued sweeps are processed and their outputs still published
  ROS_INFO_STREAM("drover: stopped (" << why << "): " << session_->summary());
  if (!params_.save_on_exit) return true;
  try {
    ROS_INFO_STREAM("drover: " << session_->save(params_.save_dir, why));
    return true;
  } catch (const std::exception& e) {
    ROS_ERROR_STREAM("drover: save on exit failed: " << e.what());
    return false;
  }
}

}  // namespace drover::ros_node
