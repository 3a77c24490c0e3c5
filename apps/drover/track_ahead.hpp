#pragma once
// The VIS's front end ahead of the replay: `drover run` reads a few measurements ahead and hands each camera frame
// the VIS will take to a worker thread that tracks it (KLT, RANSAC, detection), in time order, while the main
// thread runs the LIS and the VIS's back end on the data before it. The tracker reads nothing but the images and is
// deterministic (synchronous detection), so the tracks are the ones the main thread would have made; only the wall
// time changes (~8 ms a frame with Shi-Tomasi moves off the main thread).
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "io/reader.hpp"
#include "types/calibration.hpp"
#include "types/measurement.hpp"
#include "visual/feature_tracker.hpp"

namespace drover::cli {

// The reader's measurements, a few read ahead: each is shown to `on_read` when it is read (in order), before next()
// returns it.
class Lookahead {
 public:
  Lookahead(io::Reader& reader, std::size_t depth) : reader_(reader), depth_(depth) {}
  template <class OnRead>
  std::optional<Measurement> next(OnRead&& on_read) {
    while (!ended_ && buffer_.size() < depth_) {
      std::optional<Measurement> m = reader_.next();
      if (!m) {
        ended_ = true;
        break;
      }
      on_read(*m);
      buffer_.push_back(std::move(*m));
    }
    if (buffer_.empty()) return std::nullopt;
    Measurement m = std::move(buffer_.front());
    buffer_.pop_front();
    return m;
  }

 private:
  io::Reader& reader_;
  std::size_t depth_;
  std::deque<Measurement> buffer_;
  bool ended_ = false;
};

class TrackAhead {
 public:
  // The camera and time offset of `calibration`; the detector is this object's alone from now on.
  TrackAhead(const Calibration& calibration, std::shared_ptr<visual::KeypointDetector> detector,
             const visual::FeatureTrackerConfig& config);
  ~TrackAhead();  // stops the worker; frames not taken are dropped
  TrackAhead(const TrackAhead&) = delete;
  TrackAhead& operator=(const TrackAhead&) = delete;

  // Queues a frame for tracking; frames are tracked in the order submitted.
  void submit(const CameraFrame& frame);
  // The tracks of the oldest submitted frame, which must be `frame` (std::logic_error otherwise); rethrows what
  // tracking threw (std::invalid_argument: an image of the wrong size or type, a stamp not after the previous one).
  visual::TrackingResult take(const CameraFrame& frame);

 private:
  struct Done {
    Time t = 0;
    visual::TrackingResult tracks;
    std::exception_ptr error;
  };
  void work();

  visual::FeatureTracker tracker_;
  Time time_offset_ = 0;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<CameraFrame> todo_;
  std::deque<Done> done_;
  std::size_t waiting_ = 0;  // submitted, not yet taken
  bool stop_ = false;
  std::thread worker_;  // last: started once everything it uses exists
};

}  // namespace drover::cli
