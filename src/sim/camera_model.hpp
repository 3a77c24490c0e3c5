#pragma once
// Pinhole camera with radial-tangential distortion, rendered by casting one ray per pixel into the textured world.
// Scene value = texture colour * illumination(t, hit) * Lambert(normal) where a surface is hit, sky * illumination
// where nothing is (1 = a white surface facing the sun in daylight). Two cameras read it: the ideal one here
// (render(): grey = 255 * value + Gaussian read noise, 8-bit, linear, no gamma) and the real one of
// camera_exposure.hpp (photo-electrons over an exposure time, shot and read noise, analogue gain, auto exposure),
// which the simulator uses. Optional motion blur averages sub-frames over the exposure time.
//
// Pixel convention (as OpenCV / Kalibr): integer pixel coordinates are pixel centres, so pixel (u, v) spans
// [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5] and the image spans [-0.5, width - 0.5] x [-0.5, height - 0.5].
// Camera frame: z forward, x right, y down.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "sim/camera_exposure.hpp"
#include "sim/trajectory.hpp"
#include "sim/world.hpp"
#include "types/calibration.hpp"
#include "types/camera_distortion.hpp"
#include "types/camera.hpp"

namespace drover::sim {

// Scene lighting at time t and world point p: a factor on the surface colour (1 = daylight, 0.05 = dark barn).
// Scenarios supply it (dark segments, exposure ramps, flicker); the default is uniform daylight.
using Illumination = std::function<float(Time t, const Eigen::Vector3d& p_world)>;

// The scene as an ideal camera sees it: per pixel and channel the "ideal grey" 255 * value (mono: luma; colour:
// B, G, R), unclipped and without noise. Row-major, channels interleaved.
struct RadianceImage {
  int width = 0, height = 0, channels = 1;
  std::vector<float> grey;  // [ideal grey levels] width * height * channels
};

struct CameraModelConfig {
  CameraIntrinsics intrinsics = defaultIntrinsics();  // 640x480, fx = fy = 460, rad-tan (EuRoC-like)
  double rate_hz = 15.0;               // [Hz]
  double exposure_s = 0.01;            // [s] ideal camera's exposure (motion blur); < 1 / rate_hz. The real camera's
                                       // exposure comes from its auto exposure (exposure below)
  int motion_blur_samples = 1;         // 1 = no blur; N sub-frames averaged over the exposure (<= 64)
  // Rays per pixel side: 1 samples the scene at the pixel's centre, so texture and edges finer than a pixel alias
  // and shimmer as the view moves sub-pixel, which LK reads as motion: tracks on point-sampled frames drift ~0.14
  // px a frame (bench/RESULTS.md). N averages N x N rays spread evenly over the pixel's area, as a sensor pixel
  // integrates the light falling on it (a box filter; costs N^2 rays a pixel and sub-frame). 1 ... 4.
  int pixel_samples = 1;
  // Each ray's texture is its average over the surface the ray stands for (distance / (fx * pixel_samples), widened
  // by 1 / sqrt(cos) on slanted surfaces: the square of the ray's footprint's area) instead of its value at one point
  // (sim/texture.hpp). A few rays a pixel leave 2-4 cm texture seen from 5-15 m aliased (the farm's metal roofs:
  // moire that moves unlike the surface); this removes it at no ray cost, as more rays a pixel would at N^2 the cost.
  bool texture_filter = false;
  // Rays per pixel side where the pixel's pixel_samples^2 rays disagree: 0 = off, else in (pixel_samples, 4] with
  // pixel_samples >= 2. Texture filtered over each ray's footprint leaves a pixel's rays nearly equal; they differ
  // where an edge, a light boundary or a thin object crosses the pixel, and there a few rays leave its share of each
  // side off by up to 1 / (2 pixel_samples) of the contrast, a step that moves unlike the edge as the view moves
  // sub-pixel. Such a pixel is rendered again with edge_pixel_samples^2 rays (its first rays are dropped: they lie
  // off the finer grid), so edges get the finer box filter and flat surfaces cost pixel_samples^2 rays.
  int edge_pixel_samples = 0;
  double noise_sigma = 2.0;            // [grey levels of 255], Gaussian read noise
  bool color = false;                  // false: mono8 (as most VIO cameras); true: bgr8
  Eigen::Vector3f sky = Eigen::Vector3f(0.7f, 0.8f, 0.95f);  // linear RGB where no surface is hit (outdoors)
  bool noise = true;                   // false: no noise in either camera (exact sensors)
  CameraExposureConfig exposure;       // the real camera: sensor, gain and auto exposure (camera_exposure.hpp)
  // 640x480, fx = fy = 460, cx = 319.5, cy = 239.5, rad-tan k1 = -0.28, k2 = 0.07, p1 = 2e-4, p2 = -1e-4.
  static CameraIntrinsics defaultIntrinsics();
  // Empty when valid, else names the bad value. Supports DistortionModel::kNone and kRadialTangential (4 or 5
  // coefficients k1 k2 p1 p2 [k3]); kEquidistant is rejected.
  std::string validate() const;
};

// Lens distortion on normalised image coordinates: the shared maths of types/camera_distortion.hpp.
using drover::distortNormalized;
using drover::undistortNormalized;

// The fixed directional light of the renderer (world frame, unit, pointing towards the light): a sun 60 deg above
// the horizon at azimuth 30 deg from world x towards y, i.e. (cos 60 cos 30, cos 60 sin 30, sin 60). The same
// direction is used indoors, where it stands for light through doors and openings; the scenario's Illumination
// carries the light level.
inline Eigen::Vector3d sunDirectionWorld() {
  return {std::numbers::sqrt3 / 4.0, 0.25, std::numbers::sqrt3 / 2.0};
}
// Lambert shading factor of a surface with unit normal n_world: 0.35 + 0.65 * |n . sun| (ambient + diffuse;
// the absolute value lights both sides of thin walls the same way). In [0.35, 1].
inline float lambertFactor(const Eigen::Vector3d& n_world) {
  const double cos_incidence = n_world.dot(sunDirectionWorld());
  return 0.35f + 0.65f * static_cast<float>(std::abs(cos_incidence));
}

// Precomputes one unit ray direction per pixel in the camera frame (undistorting each pixel centre), so a frame
// is one intersect() per pixel. Thread-safe render().
class CameraRenderer {
 public:
  // Throws std::invalid_argument when config.validate() fails or a pixel cannot be undistorted.
  explicit CameraRenderer(const CameraModelConfig& config);
  // The ideal camera: the frame exposed at t (mid-exposure) from T_world_body(t) * T_body_cam. Rows render in
  // parallel; noise is counter-based (seed, frame_index, pixel), so output is identical for any thread count. With motion
  // blur, sub-frame i of N is at t + exposure * ((i + 0.5) / N - 0.5), clamped to the trajectory's span.
  // An empty `illumination` means uniform daylight (1). Throws std::out_of_range when t is outside the trajectory.
  CameraFrame render(const World& world, const SplineTrajectory& trajectory, const Eigen::Isometry3d& T_body_cam,
                     const Illumination& illumination, Time t, std::uint64_t seed, std::uint64_t frame_index,
                     bool textureless = false) const;
  // The scene before any sensor: ideal grey per pixel, motion blur (if configured) over `exposure_s` [s] centred on
  // t. Deterministic (no noise). Throws std::out_of_range when t is outside the trajectory. textureless: every
  // surface in its plain colour (the sensor-fault of sensor_faults.hpp).
  RadianceImage renderRadiance(const World& world, const SplineTrajectory& trajectory,
                               const Eigen::Isometry3d& T_body_cam, const Illumination& illumination, Time t,
                               double exposure_s, bool textureless = false) const;
  const CameraModelConfig& config() const { return config_; }

  // Pixel [px] of a camera-frame point: distort + K. Nothing when the point is not in front of the camera
  // (z <= 1e-9 m), lies outside the field of view the image covers, or falls outside the image bounds.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_cam) const;
  // Unit ray in the camera frame through pixel coordinates `pixel` [px] (undistorted to 1e-10 px).
  // Throws std::invalid_argument when the distortion model cannot be inverted there.
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel) const;
  // The precomputed unit ray through the centre of pixel (u, v) (float precision).
  const Eigen::Vector3f& ray(int u, int v) const { return rays_cam_[static_cast<std::size_t>(v) * width_ + u]; }

 private:
  struct SubFrame;
  void renderRow(const World& world, const std::vector<SubFrame>& subframes, const Illumination& illumination,
                 int v, float* row, bool textureless) const;
  // Linear RGB along `count` rays summed over the rays and the sub-frames; *luma_spread: the largest minus the
  // smallest luma of the rays (each summed over the sub-frames). ray_angle [rad]: the angle one ray stands for
  // (texture_filter), or 0.
  Eigen::Vector3f raysRadiance(const World& world, const std::vector<SubFrame>& subframes,
                               const Illumination& illumination, const Eigen::Vector3f* rays, std::size_t count,
                               bool textureless, double ray_angle, float* luma_spread) const;
  // samples^2 unit rays through the sub-pixel centres of every pixel, pixel after pixel.
  std::vector<Eigen::Vector3f> areaRays(int samples) const;

  CameraModelConfig config_;
  std::size_t width_ = 0;
  double max_r2_ = 0;                      // largest |xn|^2 of any pixel, with margin (limits project())
  std::vector<Eigen::Vector3f> rays_cam_;  // unit ray per pixel, row-major, camera frame (z forward)
  // pixel_samples > 1: pixel_samples^2 unit rays per pixel, pixel after pixel (row-major), through the pixel's
  // sub-pixel centres (u + (a + 0.5) / N - 0.5, v + (b + 0.5) / N - 0.5)
  std::vector<Eigen::Vector3f> rays_area_;
  std::vector<Eigen::Vector3f> rays_edge_;  // edge_pixel_samples > 0: the same for edge_pixel_samples^2 rays
};

}  // namespace drover::sim
