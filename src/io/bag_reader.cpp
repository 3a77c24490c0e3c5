#include "io/bag_reader.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <set>

#include "io/error.hpp"
#include "io/ros_messages.hpp"
#include "io/ros_pointcloud.hpp"

namespace drover::io {
namespace {

constexpr const char* kStreamNames[] = {"lidar", "imu", "image"};

struct AcceptedType {
  std::string_view type, md5;
};

std::vector<AcceptedType> acceptedTypes(int stream) {
  switch (stream) {
    case 0: return {{ros::kPointCloud2, ros::kPointCloud2Md5}};
    case 1: return {{ros::kImu, ros::kImuMd5}};
    default: return {{ros::kImage, ros::kImageMd5}, {ros::kCompressedImage, ros::kCompressedImageMd5}};
  }
}

std::string timeString(Time t) {
  std::string ns = std::to_string(t % kNanosPerSecond);
  return std::to_string(t / kNanosPerSecond) + "." + std::string(9 - ns.size(), '0') + ns;
}

bool heapAfter(Time ta, std::uint64_t sa, Time tb, std::uint64_t sb) { return ta > tb || (ta == tb && sa > sb); }

}  // namespace

BagReader::BagReader(const std::string& path, const DatasetOptions& options)
    : path_(path), options_(options), file_(std::make_unique<bag::BagFile>(path)) {
  index_ = file_->readIndex();
  if (index_.scanned)
    warnings_.push_back("bag is not indexed (the recording was not closed cleanly): read by scanning its chunks" +
                        (index_.unread_tail_bytes > 0
                             ? "; the last " + std::to_string(index_.unread_tail_bytes) + " bytes were incomplete"
                             : std::string()));
  topics_[kLidar] = options.load_lidar ? options.lidar_topic : "";
  topics_[kImu] = options.load_imu ? options.imu_topic : "";
  topics_[kImage] = options.load_images ? options.image_topic : "";
  std::fill(std::begin(latest_), std::end(latest_), std::numeric_limits<Time>::min());
  last_returned_ = std::numeric_limits<Time>::min();
  readGroundTruth();  // before selectConnections frees the full index
  selectConnections();
}

void BagReader::readGroundTruth() {
  const std::string& topic = options_.ground_truth_topic;
  if (topic.empty()) return;
  std::set<std::uint32_t> conns;
  for (const bag::Connection& c : index_.connections) {
    if (c.topic != topic) continue;
    if (c.type != ros::kOdometry)
      fail(path_, "topic " + topic, "configured as the ground-truth topic but has type " + c.type + ", expected " +
                                        std::string(ros::kOdometry));
    if (c.md5sum != "*" && c.md5sum != ros::kOdometryMd5)
      fail(path_, "topic " + topic, "message type " + c.type + " has md5sum " + c.md5sum + ", expected " +
                                        std::string(ros::kOdometryMd5) + " (a different message definition)");
    conns.insert(c.id);
  }
  if (conns.empty()) {
    warnings_.push_back("ground-truth topic " + topic + " is not in the bag");
    return;
  }
  std::uint32_t n = 0;
  for (const bag::IndexEntry& e : index_.entries) {
    if (!conns.count(e.conn)) continue;
    const std::string where = "topic " + topic + " message " + std::to_string(n++) + ", bag time " + timeString(e.time);
    const std::vector<std::uint8_t> data = file_->copyMessageData(index_, e);
    ros::Odometry o;
    try {
      o = ros::decodeOdometry(data.data(), data.size());
    } catch (const ros::MessageError& err) {
      fail(path_, where, err.what());
    }
    if (o.child_frame_id != "imu" && o.child_frame_id != "lidar")
      fail(path_, where, "child_frame_id '" + o.child_frame_id.substr(0, 40) +
                             "' is neither imu nor lidar: the ground truth must be the IMU's or the lidar's pose");
    if (ground_truth_.body_frame.empty()) ground_truth_.body_frame = o.child_frame_id;
    if (o.child_frame_id != ground_truth_.body_frame)
      fail(path_, where, "child_frame_id '" + o.child_frame_id + "' differs from the first message's '" +
                             ground_truth_.body_frame + "'");
    if (!o.T_frame_child.matrix().allFinite()) fail(path_, where, "pose is not finite");
    Trajectory& poses = ground_truth_.poses;
    if (!poses.empty() && o.t <= poses.back().t) {
      dropMeasurement(path_ + " (" + where + "): dropped: ground-truth stamp " + timeString(o.t) +
                      " is not after the previous one's " + timeString(poses.back().t));
      continue;
    }
    poses.push_back({o.t, o.T_frame_child});
  }
}

void BagReader::selectConnections() {
  struct Use {
    Stream stream;
    bool compressed;
  };
  std::map<std::uint32_t, Use> uses;
  bool found[kStreamCount] = {false, false, false};
  for (const bag::Connection& c : index_.connections) {
    for (int s = 0; s < kStreamCount; ++s) {
      if (topics_[s].empty() || c.topic != topics_[s]) continue;
      std::string expected;
      bool ok = false;
      for (const AcceptedType& a : acceptedTypes(s)) {
        expected += (expected.empty() ? "" : " or ") + std::string(a.type);
        if (c.type != a.type) continue;
        if (c.md5sum != "*" && c.md5sum != a.md5)
          fail(path_, "topic " + c.topic, "message type " + c.type + " has md5sum " + c.md5sum + ", expected " +
                                              std::string(a.md5) + " (a different message definition)");
        ok = true;
      }
      if (!ok)
        fail(path_, "topic " + c.topic, "configured as the " + std::string(kStreamNames[s]) + " topic but has type " +
                                            c.type + ", expected " + expected);
      uses[c.id] = {static_cast<Stream>(s), c.type == ros::kCompressedImage};
      found[s] = true;
    }
  }
  bool any_enabled = false, any_found = false;
  for (int s = 0; s < kStreamCount; ++s) {
    any_enabled = any_enabled || !topics_[s].empty();
    any_found = any_found || found[s];
    if (!topics_[s].empty() && !found[s])
      warnings_.push_back(std::string(kStreamNames[s]) + " topic " + topics_[s] + " is not in the bag");
  }
  if (any_enabled && !any_found) {
    std::set<std::string> present;
    for (const bag::Connection& c : index_.connections) present.insert(c.topic + " (" + c.type + ")");
    std::string list;
    for (const std::string& p : present) list += (list.empty() ? "" : ", ") + p;
    fail(path_, "", "none of the configured topics (lidar '" + topics_[kLidar] + "', imu '" + topics_[kImu] +
                        "', image '" + topics_[kImage] + "') is in the bag; it contains: " +
                        (list.empty() ? "no topics" : list));
  }
  std::uint32_t per_topic[kStreamCount] = {0, 0, 0};
  for (const bag::IndexEntry& e : index_.entries) {
    const auto it = uses.find(e.conn);
    if (it == uses.end()) continue;
    const Stream s = it->second.stream;
    selected_.push_back({e, s, it->second.compressed, per_topic[s]++});
  }
  for (int s = 0; s < kStreamCount; ++s) remaining_[s] = total_[s] = per_topic[s];
  // The selection holds all we need; free the full index of long bags.
  std::vector<bag::IndexEntry>().swap(index_.entries);
}

std::string BagReader::record(const Selected& s) const {
  return "topic " + topics_[s.stream] + " message " + std::to_string(s.topic_index) + ", bag time " +
         timeString(s.entry.time);
}

void BagReader::decodeNext() {
  const Selected& sel = selected_[cursor_++];
  const auto [data, size] = file_->messageData(index_, sel.entry);
  Measurement m;
  try {
    if (sel.stream == kLidar) {
      ros::DecodedCloud cloud = ros::decodePointCloud2(data, size);
      stats_.nonfinite_points_dropped += cloud.dropped_nonfinite;
      m = std::move(cloud.scan);
    } else if (sel.stream == kImu) {
      m = ros::decodeImu(data, size);
    } else {
      CameraFrame f = sel.compressed_image ? ros::decodeCompressedImage(data, size) : ros::decodeImage(data, size);
      f.source = path_ + ":" + topics_[kImage] + "#" + std::to_string(sel.topic_index);
      m = std::move(f);
    }
  } catch (const ros::MessageError& e) {
    fail(path_, record(sel), e.what());
  }
  const Time t = measurementTime(m);
  --remaining_[sel.stream];
  ++stats_.messages_decoded;
  // A glitch of the IMU or its driver, like a spike: dropped with a warning, not the end of the bag.
  if (const auto* s = std::get_if<ImuSample>(&m); s && (!s->omega_imu.allFinite() || !s->acc_imu.allFinite())) {
    dropMeasurement(path_ + " (" + record(sel) + "): dropped: angular velocity or linear acceleration is not finite");
    return;
  }
  // A driver that repeats or reorders a stamp: the message is dropped (a warning for the caller), so that the
  // stream stays strictly increasing per topic, which the reorder buffer relies on.
  if (t <= latest_[sel.stream]) {
    dropMeasurement(path_ + " (" + record(sel) + "): dropped: stamp " + timeString(t) +
                    (t == latest_[sel.stream] ? " repeats" : " is before") + " the previous message's " +
                    timeString(latest_[sel.stream]) + " on this topic");
    return;
  }
  latest_[sel.stream] = t;
  heap_.push_back({std::move(m), t, sel.entry.time, seq_++, &sel});
  std::push_heap(heap_.begin(), heap_.end(),
                 [](const Pending& a, const Pending& b) { return heapAfter(a.t, a.seq, b.t, b.seq); });
}

bool BagReader::releasable() const {
  const Pending& top = heap_.front();
  if (cursor_ < selected_.size() && selected_[cursor_].entry.time - top.record_time > kReorderWindow) return true;
  for (int s = 0; s < kStreamCount; ++s)
    if (remaining_[s] > 0 && latest_[s] < top.t) return false;  // stream s may still bring an earlier stamp
  return true;
}

std::optional<Measurement> BagReader::pop() {
  std::pop_heap(heap_.begin(), heap_.end(),
                [](const Pending& a, const Pending& b) { return heapAfter(a.t, a.seq, b.t, b.seq); });
  Pending p = std::move(heap_.back());
  heap_.pop_back();
  // Returning it would break the stream's time order; dropping it loses one late message.
  if (p.t < last_returned_) {
    dropMeasurement(path_ + " (" + record(*p.source) + "): dropped: header stamp " + timeString(p.t) +
                    " is earlier than the already returned measurement at " + timeString(last_returned_) +
                    " (it lags the bag record time by more than " +
                    std::to_string(kReorderWindow / kNanosPerSecond) + " s relative to the other topics)");
    return std::nullopt;
  }
  last_returned_ = p.t;
  return std::move(p.m);
}

std::optional<Measurement> BagReader::next() {
  while (true) {
    if (!heap_.empty() && (releasable() || cursor_ >= selected_.size())) {
      if (std::optional<Measurement> m = pop()) return m;
      continue;
    }
    if (cursor_ < selected_.size()) {
      decodeNext();
      continue;
    }
    return std::nullopt;
  }
}

std::string BagReader::describe() const {
  std::string s = "ROS bag " + path_ + ":";
  for (int k = 0; k < kStreamCount; ++k)
    if (!topics_[k].empty()) s += std::string(" ") + kStreamNames[k] + " " + topics_[k] + " (" +
                                  std::to_string(total_[k]) + " msgs)";
  if (!ground_truth_.poses.empty())
    s += " ground truth " + options_.ground_truth_topic + " (" + std::to_string(ground_truth_.poses.size()) +
         " poses of the " + ground_truth_.body_frame + ")";
  for (const std::string& w : warnings_) s += "; " + w;
  return s;
}

std::unique_ptr<Reader> openBag(const std::string& path, const DatasetOptions& options) {
  return std::make_unique<BagReader>(path, options);
}

}  // namespace drover::io
