#pragma once
// The camera of bench_memory_hour: the frames of a simulated dataset of the same course and seed (drover sim
// --config config/farm_sim.yaml, 2x2 rays a pixel) replayed every lap. Rendering the hour's ~58,000 frames again
// would take ~2.3 h on 2 cores (0.47 simulated s a wall s with the camera), so they are read back from disk, one at
// a time. The course's path is the same every lap (only each lap's sensor noise differs), so the frames match every
// lap's ground truth; only their image noise repeats.
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>

#include "io/dataset.hpp"
#include "types/measurement.hpp"

namespace drover::bench {

class CameraReplay {
 public:
  // Throws io::IoError when `dir` is not a readable simulated dataset.
  explicit CameraReplay(std::string dir) : dir_(std::move(dir)) { reader_ = open(); }
  const Calibration& calibration() const { return reader_->calibration(); }
  // Reads the lap's frames from the start, their stamps moved by offset [ns].
  void startLap(Time offset) {
    reader_ = open();
    offset_ = offset;
    next_ = fetch();
  }
  // Hands `push` every frame of the lap stamped at or before t [ns, with the offset], in time order.
  template <class Push>
  void pushUpTo(Time t, Push&& push) {
    while (next_ && next_->t <= t) {
      CameraFrame frame = std::move(*next_);
      next_ = fetch();
      push(std::move(frame));
    }
  }

 private:
  std::unique_ptr<io::Reader> open() const {
    io::DatasetOptions options;
    options.load_lidar = false;
    options.load_imu = false;
    return io::openDataset(dir_, "sim", options);
  }
  std::optional<CameraFrame> fetch() {
    while (std::optional<Measurement> m = reader_->next()) {
      if (auto* frame = std::get_if<CameraFrame>(&*m)) {
        frame->t += offset_;
        return std::move(*frame);
      }
    }
    return std::nullopt;
  }
  std::string dir_;
  std::unique_ptr<io::Reader> reader_;
  Time offset_ = 0;
  std::optional<CameraFrame> next_;
};

}  // namespace drover::bench
