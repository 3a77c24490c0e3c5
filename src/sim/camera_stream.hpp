#pragma once
// The simulated camera as the simulator runs it: the renderer's radiance read by the sensor at the exposure and
// gain the auto exposure chose from the frames before (camera_exposure.hpp), or the ideal camera when the exposure
// model is disabled. Frames must be taken in order; each frame's rows render in parallel.
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>

#include "sim/camera_exposure.hpp"
#include "sim/camera_model.hpp"

namespace drover::sim {

// What a sensor fault does to one frame (sensor_faults.hpp).
struct FrameCondition {
  bool blackout = false;     // no light reaches the sensor
  bool textureless = false;  // surfaces in their plain colours
};

class CameraStream {
 public:
  // Throws std::invalid_argument when config.validate() fails.
  explicit CameraStream(const CameraModelConfig& config);
  // The next frame, exposed (mid-exposure) at true time t; frame_index counts from 0 and seeds the noise with
  // `seed`. The first frame settles the auto exposure on its own scene before it is taken. Motion blur spans the
  // frame's own exposure time. A blacked-out frame meters as black, so the auto exposure opens up during it.
  CameraFrame next(const World& world, const SplineTrajectory& trajectory, const Eigen::Isometry3d& T_body_cam,
                   const Illumination& illumination, Time t, std::uint64_t seed, std::uint64_t frame_index,
                   FrameCondition condition = {});
  // The setting the last frame was taken with (the ideal camera: config exposure_s, gain 1).
  const ExposureSetting& lastSetting() const { return last_; }
  bool lastAtFloor() const { return last_at_floor_; }
  const CameraRenderer& renderer() const { return renderer_; }

 private:
  CameraRenderer renderer_;
  CameraSensor sensor_;
  AutoExposure auto_exposure_;
  bool settled_ = false;
  ExposureSetting last_;
  bool last_at_floor_ = false;
};

}  // namespace drover::sim
