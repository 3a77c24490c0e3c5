// CameraStream: radiance -> sensor at the auto exposure's setting -> the next setting (camera_stream.hpp).
#include "sim/camera_stream.hpp"

#include <algorithm>
#include <cstdint>

namespace drover::sim {

CameraStream::CameraStream(const CameraModelConfig& config)
    : renderer_(config),
      sensor_(config.exposure, config.noise),
      auto_exposure_(config.exposure, config.exposure_s, config.rate_hz),
      last_{config.exposure_s, 1.0} {}

CameraFrame CameraStream::next(const World& world, const SplineTrajectory& trajectory,
                               const Eigen::Isometry3d& T_body_cam, const Illumination& illumination, Time t,
                               std::uint64_t seed, std::uint64_t frame_index, FrameCondition condition) {
  const CameraModelConfig& config = renderer_.config();
  const bool flat = condition.textureless;
  if (!config.exposure.enabled) {
    CameraFrame frame = renderer_.render(world, trajectory, T_body_cam, illumination, t, seed, frame_index, flat);
    if (condition.blackout) std::fill(frame.image.data.begin(), frame.image.data.end(), std::uint8_t{0});
    return frame;
  }
  ExposureSetting setting = auto_exposure_.current();
  RadianceImage radiance =
      renderer_.renderRadiance(world, trajectory, T_body_cam, illumination, t, setting.exposure_s, flat);
  if (!settled_) {
    settled_ = true;
    auto_exposure_.settle(sensor_, radiance);
    const bool blur_span_changed = auto_exposure_.current().exposure_s != setting.exposure_s;
    setting = auto_exposure_.current();
    if (config.motion_blur_samples > 1 && blur_span_changed)
      radiance = renderer_.renderRadiance(world, trajectory, T_body_cam, illumination, t, setting.exposure_s, flat);
  }
  if (condition.blackout) std::fill(radiance.grey.begin(), radiance.grey.end(), 0.0f);
  CameraFrame frame;
  frame.t = t;
  frame.camera_id = 0;
  frame.source = "sim";
  frame.image = sensor_.expose(radiance, setting, seed, frame_index);
  last_ = setting;
  last_at_floor_ = auto_exposure_.atFloor();
  auto_exposure_.update(meanGrey(frame.image));
  return frame;
}

}  // namespace drover::sim
