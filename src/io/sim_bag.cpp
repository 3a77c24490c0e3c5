// `drover sim --format bag` (layout in io/sim_bag.hpp).
#include "io/sim_bag.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "io/ros_serialize.hpp"
#include "io/text_parsing.hpp"

namespace drover::io {
namespace {

bag::WriterOptions writerOptions(bool overwrite) {
  bag::WriterOptions o;
  o.overwrite = overwrite;
  o.replace_hint = "use --force to replace it";
  return o;
}

// Discrete-time variance of one sample of white noise of `density` [unit/sqrt(Hz)] at `rate_hz`: sigma_d^2 =
// density^2 / dt (the discretisation of Kalibr's IMU noise model, sigma_d = sigma / sqrt(dt)).
double sampleVariance(double density, double rate_hz) { return density * density * rate_hz; }

const char* kSensorNames[] = {"IMU sample", "lidar scan", "camera frame"};  // Measurement's alternatives

}  // namespace

void SimBagWriter::checkOutput(const std::string& path, bool overwrite) {
  bag::BagWriter::checkOutput(path, writerOptions(overwrite));
}

SimBagWriter::SimBagWriter(const std::string& path, const SimDatasetDescription& description,
                           std::vector<SimGroundTruthState> ground_truth, bool overwrite)
    : writer_(path, writerOptions(overwrite)), description_(description), ground_truth_(std::move(ground_truth)) {
  for (std::size_t i = 1; i < ground_truth_.size(); ++i)
    if (ground_truth_[i].t <= ground_truth_[i - 1].t)
      throw std::invalid_argument("sim bag writer: ground-truth times must increase (sample " + std::to_string(i) +
                                  ")");
  const SimScenarioInfo& s = description.scenario;
  // Topics in LVI-SAM's order of importance; connection ids follow.
  if (s.has_lidar) lidar_conn_ = writer_.addConnection(kSimBagLidarTopic, ros::pointCloud2Type());
  if (s.has_imu) imu_conn_ = writer_.addConnection(kSimBagImuTopic, ros::imuType());
  if (s.has_camera) image_conn_ = writer_.addConnection(kSimBagImageTopic, ros::imageType());
  ground_truth_conn_ = writer_.addConnection(kSimBagGroundTruthTopic, ros::odometryType());
  std::fill(std::begin(last_stamp_), std::end(last_stamp_), std::numeric_limits<Time>::min());
  last_any_ = std::numeric_limits<Time>::min();
}

void SimBagWriter::push(std::uint32_t conn, Time record, std::string data) {
  pending_.push({record, seq_++, conn, std::move(data)});
}

void SimBagWriter::release(Time bound) {
  // Ground truth up to the bound joins the queue first, so that ties keep it ahead of sensor data of the same time.
  for (; ground_truth_next_ < ground_truth_.size() && ground_truth_[ground_truth_next_].t + kSimBagEpoch <= bound;
       ++ground_truth_next_) {
    const SimGroundTruthState& g = ground_truth_[ground_truth_next_];
    ros::Odometry o;
    o.t = g.t + kSimBagEpoch;
    o.frame_id = "world";
    o.child_frame_id = "imu";
    o.T_frame_child = g.T_world_imu;
    o.linear = g.v_imu;
    o.angular = g.omega_imu;
    push(ground_truth_conn_, o.t, ros::serializeOdometry(o, static_cast<std::uint32_t>(counts_.ground_truth++)));
  }
  while (!pending_.empty() && pending_.top().record <= bound) {
    const Pending& p = pending_.top();
    writer_.write(p.conn, p.record, p.data);
    pending_.pop();
  }
}

void SimBagWriter::add(Measurement&& m) {
  const Time t = measurementTime(m);
  const std::size_t sensor = m.index();
  if (t <= last_stamp_[sensor] || t < last_any_)
    throw std::invalid_argument(std::string("sim bag writer: ") + kSensorNames[sensor] + " at " + formatSeconds(t) +
                                " s comes after data stamped " +
                                formatSeconds(std::max(last_stamp_[sensor], last_any_)) + " s");
  last_stamp_[sensor] = last_any_ = t;
  const Time stamp = t + kSimBagEpoch;
  if (auto* imu = std::get_if<ImuSample>(&m)) {
    imu->t = stamp;
    const SimSensorInfo& s = description_.sensors;
    const ros::ImuVariances variances{sampleVariance(s.gyro_noise_density, s.imu_rate_hz),
                                      sampleVariance(s.accel_noise_density, s.imu_rate_hz)};
    push(imu_conn_, stamp, ros::serializeImu(*imu, static_cast<std::uint32_t>(counts_.imu++), "imu", variances));
  } else if (auto* scan = std::get_if<LidarScan>(&m)) {
    // Published once its last point is measured (its stamp is the sweep's start).
    Time last_point = 0;
    for (const LidarPoint& p : scan->points)
      last_point = std::max(last_point, static_cast<Time>(std::llround(static_cast<double>(p.time_offset) * 1e9)));
    scan->t = stamp;
    counts_.lidar_points += scan->points.size();
    push(lidar_conn_, stamp + last_point,
         ros::serializePointCloud2(*scan, static_cast<std::uint32_t>(counts_.lidar++), "lidar"));
  } else {
    auto& frame = std::get<CameraFrame>(m);
    frame.t = stamp;
    push(image_conn_, stamp, ros::serializeImage(frame, static_cast<std::uint32_t>(counts_.camera++), "camera"));
  }
  // Whatever comes later is stamped at or after `stamp` and recorded no earlier: all up to it can be written.
  release(stamp);
  counts_.bytes = writer_.counts().bytes;
}

void SimBagWriter::finish() {
  release(std::numeric_limits<Time>::max());
  writer_.finish();
  counts_.bytes = writer_.counts().bytes;
}

}  // namespace drover::io
