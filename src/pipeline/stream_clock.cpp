#include "pipeline/stream_clock.hpp"

namespace drover::pipeline {

StreamClock::StreamClock(Time clock_jump, Time sensor_gap) : clock_jump_(clock_jump), sensor_gap_(sensor_gap) {}

StreamClock::Verdict StreamClock::check(Stream stream, Time t) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (jumped_) return {Kind::kIgnore, 0};
  std::optional<Time>& newest = newest_[static_cast<std::size_t>(stream)];
  if (!newest) {
    newest = t;
    return {Kind::kAdmit, 0};
  }
  const Time previous = *newest;
  if (t < previous - clock_jump_) {
    jumped_ = true;
    return {Kind::kJump, previous};
  }
  if (t <= previous) return {Kind::kAdmit, previous};  // out of order: the stage skips it
  newest = t;
  // The IMU's gaps are the LIS's to report (it knows what they do to the fusion).
  if (stream != Stream::kImu && t - previous > sensor_gap_) return {Kind::kRestart, previous};
  return {Kind::kAdmit, previous};
}

const char* StreamClock::name(Stream stream) {
  switch (stream) {
    case Stream::kImu: return "imu";
    case Stream::kLidar: return "lidar";
    case Stream::kCamera: return "camera";
  }
  return "?";
}

}  // namespace drover::pipeline
