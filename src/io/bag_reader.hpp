#pragma once
// ROS1 bag (v2.0) reader: the lidar, IMU and camera topics named in DatasetOptions as one time-ordered stream.
//
// Order: the bag index is read up front and the selected messages are visited in bag record-time order (chunk by
// chunk, one decompressed chunk cached). Measurement times are the messages' header stamps, which lag or lead the
// record times by sensor/driver latency (a lidar sweep is recorded ~0.1-0.2 s after its start stamp), so decoded
// measurements pass through a reorder buffer: one is returned once every topic still holding messages has shown
// a later stamp, or once the bag's record time has moved kReorderWindow past it. Within a topic, a message whose
// stamp does not increase (duplicate or backwards) is dropped, and so is a measurement older than one already
// returned (its stamp lags its record time by more than the window): each is counted in drops() with a notice
// naming the message, rather than silently out of order. Memory stays bounded by the window's messages.
//
// Calibration comes from DatasetOptions::calibration (bags carry none); time offsets in it are not applied here.
// Ground truth: the nav_msgs/Odometry messages on DatasetOptions::ground_truth_topic (a simulated bag's, `drover
// sim --format bag`), read up front: T_world_body at each header stamp, body_frame = the messages' child_frame_id,
// which must be "imu" or "lidar" and the same in every message; a stamp not after the previous one is dropped with a
// notice (drops()), a non-finite pose or another type on the topic is an IoError. No topic configured: none.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "io/bag_format.hpp"
#include "io/dataset.hpp"
#include "io/reader.hpp"

namespace drover::io {

struct BagReadStats {
  std::size_t messages_decoded = 0;          // on the configured topics
  std::size_t nonfinite_points_dropped = 0;  // lidar points with NaN/inf fields (organised clouds)
};

class BagReader final : public Reader {
 public:
  // Bag record time a decoded measurement may wait for messages with earlier stamps [ns].
  static constexpr Time kReorderWindow = 2 * kNanosPerSecond;

  // Reads the index; throws IoError for a malformed bag, a configured topic of the wrong message type, or when
  // none of the enabled topics is in the bag (the error lists the bag's topics). A single missing topic is
  // reported in warnings() and describe().
  BagReader(const std::string& path, const DatasetOptions& options);

  std::optional<Measurement> next() override;
  const Calibration& calibration() const override { return options_.calibration; }
  const GroundTruth& groundTruth() const override { return ground_truth_; }
  std::string describe() const override;

  const BagReadStats& stats() const { return stats_; }
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  enum Stream : int { kLidar = 0, kImu = 1, kImage = 2, kStreamCount = 3 };
  struct Selected {
    bag::IndexEntry entry;
    Stream stream;
    bool compressed_image;
    std::uint32_t topic_index;  // position on its topic in record-time order, for error messages
  };
  struct Pending {
    Measurement m;
    Time t;
    Time record_time;
    std::uint64_t seq;
    const Selected* source;
  };

  void selectConnections();
  void readGroundTruth();
  void decodeNext();
  bool releasable() const;
  std::optional<Measurement> pop();  // nullopt: the popped measurement was dropped as late
  std::string record(const Selected& s) const;

  std::string path_;
  DatasetOptions options_;
  GroundTruth ground_truth_;
  std::unique_ptr<bag::BagFile> file_;
  bag::BagIndex index_;
  std::string topics_[kStreamCount];
  std::vector<Selected> selected_;
  std::size_t cursor_ = 0;
  std::vector<Pending> heap_;  // min-heap on (t, seq)
  std::uint64_t seq_ = 0;
  std::size_t remaining_[kStreamCount] = {0, 0, 0};
  std::size_t total_[kStreamCount] = {0, 0, 0};
  Time latest_[kStreamCount];
  Time last_returned_;
  BagReadStats stats_;
  std::vector<std::string> warnings_;
};

std::unique_ptr<Reader> openBag(const std::string& path, const DatasetOptions& options);

}  // namespace drover::io
