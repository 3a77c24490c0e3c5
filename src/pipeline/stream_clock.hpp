#pragma once
// The live system's view of its input clocks: each stream's newest stamp, from which a clock that jumped back (a
// restarted recording, a reset clock) and a lidar or camera that fell silent and came back are told apart from an
// ordinary message out of order (which the stage that gets it skips). Thread-safe; one stream per pushing thread.
#include <array>
#include <mutex>
#include <optional>

#include "types/time.hpp"

namespace drover::pipeline {

class StreamClock {
 public:
  enum class Stream { kImu = 0, kLidar = 1, kCamera = 2 };
  enum class Kind {
    kAdmit,    // take it
    kRestart,  // take it; a lidar or camera silent for more than sensor_gap_s before it (`previous` is its last)
    kJump,     // the clock jumped back more than clock_jump_s (`previous` is the stream's newest): ignore it
    kIgnore,   // a clock jumped back earlier: all input is ignored from then on
  };
  struct Verdict {
    Kind kind = Kind::kAdmit;
    Time previous = 0;  // [ns]
  };

  StreamClock(Time clock_jump, Time sensor_gap);  // [ns] each
  Verdict check(Stream stream, Time t);
  static const char* name(Stream stream);  // "imu", "lidar", "camera"

 private:
  const Time clock_jump_, sensor_gap_;
  std::mutex mutex_;
  std::array<std::optional<Time>, 3> newest_;
  bool jumped_ = false;
};

}  // namespace drover::pipeline
