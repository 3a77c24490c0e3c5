#include "apps/drover/track_ahead.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "visual/camera_model.hpp"

namespace drover::cli {

TrackAhead::TrackAhead(const Calibration& calibration, std::shared_ptr<visual::KeypointDetector> detector,
                       const visual::FeatureTrackerConfig& config)
    : tracker_(visual::CameraModel(calibration.camera), std::move(detector), config),
      time_offset_(calibration.camera_time_offset),
      worker_([this] { work(); }) {}

TrackAhead::~TrackAhead() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  worker_.join();
}

void TrackAhead::submit(const CameraFrame& frame) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    todo_.push_back(frame);
    ++waiting_;
  }
  changed_.notify_all();
}

visual::TrackingResult TrackAhead::take(const CameraFrame& frame) {
  Done done;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    if (waiting_ == 0)
      throw std::logic_error("TrackAhead::take: no frame submitted (frame at " + std::to_string(frame.t) + " ns)");
    changed_.wait(lock, [this] { return !done_.empty(); });
    done = std::move(done_.front());
    done_.pop_front();
    --waiting_;
  }
  if (done.t != frame.t)
    throw std::logic_error("TrackAhead::take: the oldest tracked frame is at " + std::to_string(done.t) +
                           " ns, not the frame at " + std::to_string(frame.t) + " ns");
  if (done.error) std::rethrow_exception(done.error);
  return std::move(done.tracks);
}

void TrackAhead::work() {
  for (;;) {
    CameraFrame frame;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return stop_ || !todo_.empty(); });
      if (stop_) return;
      frame = std::move(todo_.front());
      todo_.pop_front();
    }
    Done done;
    done.t = frame.t;
    try {
      done.tracks = tracker_.track(frame.t + time_offset_, visual::imageView(frame.image));
    } catch (...) {
      done.error = std::current_exception();
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_.push_back(std::move(done));
    }
    changed_.notify_all();
  }
}

}  // namespace drover::cli
