// CameraRenderer::renderRadiance: one ray per pixel, or pixel_samples^2 over its area (and per motion-blur
// sub-frame), edge_pixel_samples^2 where those disagree, into the world, texture * light * Lambert shading.
// CameraRenderer::render: the ideal camera on top of it, counter-based Gaussian read noise and 8-bit quantisation
// (linear, no gamma curve). The sensor with exposure and gain is camera_exposure.cpp.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/camera_model.hpp"
#include "sim/gaussian_quantiles.hpp"
#include "sim/random.hpp"
#include "sim/texture.hpp"

namespace drover::sim {

struct CameraRenderer::SubFrame {
  Time t = 0;                     // [ns] sub-frame time
  Eigen::Matrix3d R_world_cam;    // camera orientation at t
  Eigen::Vector3d origin_world;   // camera centre at t [m]
};

namespace {

constexpr double kSkyDistance = 1e4;  // [m] where the sky's illumination is evaluated along a ray that hits nothing

float lightAt(const Illumination& illumination, Time t, const Eigen::Vector3d& p_world) {
  return illumination ? illumination(t, p_world) : 1.0f;
}

// Slanted surfaces stretch a ray's footprint by 1 / cos(incidence); this bounds it at grazing incidence.
constexpr double kMinFootprintCos = 0.05;

// The width [m] of surface a ray of `ray_angle` [rad] stands for where it hits: the side of a square of its
// footprint's area (distance * angle by distance * angle / cos). 0 when ray_angle is 0 (point sampling).
double footprintAt(const Hit& hit, const Eigen::Vector3d& direction, double ray_angle) {
  if (!(ray_angle > 0)) return 0.0;
  const double cos_incidence = std::max(std::abs(hit.normal.dot(direction)), kMinFootprintCos);
  return hit.distance * ray_angle / std::sqrt(cos_incidence);
}

// Linear RGB arriving along one camera ray at one sub-frame.
// textureless: the surface's plain colour (the white-walls material with the surface's colour) instead of its texture.
// ray_angle: the angle [rad] one ray stands for when textures are filtered (CameraModelConfig::texture_filter), or 0.
Eigen::Vector3f radiance(const World& world, const Illumination& illumination, const Eigen::Vector3f& sky,
                         Time t, const Eigen::Matrix3d& R_world_cam, const Eigen::Vector3d& origin_world,
                         const Eigen::Vector3d& ray_cam, bool textureless, double ray_angle) {
  const Ray ray{origin_world, R_world_cam * ray_cam};
  if (const std::optional<Hit> hit = world.intersect(ray)) {
    const float light = lightAt(illumination, t, hit->point) * lambertFactor(hit->normal);
    if (textureless) {
      Material plain = *hit->material;
      plain.texture = Texture::kWhite;
      return shade(plain, hit->uv) * light;
    }
    return shade(*hit->material, hit->uv, footprintAt(*hit, ray.direction.normalized(), ray_angle)) * light;
  }
  return sky * lightAt(illumination, t, ray.origin + kSkyDistance * ray.direction);
}

// Luma of linear RGB (ITU-R BT.601 weights): the mono camera's grey.
float luma(const Eigen::Vector3f& rgb) { return 0.299f * rgb.x() + 0.587f * rgb.y() + 0.114f * rgb.z(); }

// A pixel is rendered again with edge_pixel_samples^2 rays when its rays' luma spread exceeds this share of its mean
// luma plus kEdgeSpreadFloor [linear units, 1 = white in daylight]. Relative, because the sensor's gain multiplies a
// dark scene's contrasts up to full scale.
constexpr float kEdgeSpread = 0.25f;
constexpr float kEdgeSpreadFloor = 1e-6f;

}  // namespace

Eigen::Vector3f CameraRenderer::raysRadiance(const World& world, const std::vector<SubFrame>& subframes,
                                             const Illumination& illumination, const Eigen::Vector3f* rays,
                                             std::size_t count, bool textureless, double ray_angle,
                                             float* luma_spread) const {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d ray_cam = rays[k].cast<double>();
    Eigen::Vector3f rgb = Eigen::Vector3f::Zero();
    for (const SubFrame& s : subframes)
      rgb += radiance(world, illumination, config_.sky, s.t, s.R_world_cam, s.origin_world, ray_cam, textureless,
                      ray_angle);
    const float y = luma(rgb);
    lo = std::min(lo, y);
    hi = std::max(hi, y);
    sum += rgb;
  }
  *luma_spread = hi - lo;
  return sum;
}

void CameraRenderer::renderRow(const World& world, const std::vector<SubFrame>& subframes,
                               const Illumination& illumination, int v, float* row, bool textureless) const {
  const int width = config_.intrinsics.width;
  const int n = config_.pixel_samples, m = config_.edge_pixel_samples;
  const double fx = config_.intrinsics.fx;
  const double ray_angle = config_.texture_filter ? 1.0 / (fx * n) : 0.0;
  const double edge_ray_angle = config_.texture_filter && m > 0 ? 1.0 / (fx * m) : 0.0;
  const std::size_t per_pixel = static_cast<std::size_t>(n * n), per_edge_pixel = static_cast<std::size_t>(m * m);
  const Eigen::Vector3f* rays = rays_area_.empty() ? rays_cam_.data() : rays_area_.data();
  const auto subframes_n = static_cast<float>(subframes.size());
  for (int u = 0; u < width; ++u) {
    const std::size_t pixel = static_cast<std::size_t>(v) * width_ + static_cast<std::size_t>(u);
    float spread = 0;
    std::size_t count = per_pixel;
    Eigen::Vector3f rgb = raysRadiance(world, subframes, illumination, rays + pixel * per_pixel, per_pixel,
                                       textureless, ray_angle, &spread);
    if (m > 0 && spread > kEdgeSpread * luma(rgb) / static_cast<float>(count) + kEdgeSpreadFloor * subframes_n) {
      count = per_edge_pixel;
      rgb = raysRadiance(world, subframes, illumination, rays_edge_.data() + pixel * count, count, textureless,
                         edge_ray_angle, &spread);
    }
    rgb *= 1.0f / subframes_n * (1.0f / static_cast<float>(count)) * 255.0f;
    if (!config_.color) {
      row[u] = luma(rgb);
    } else {
      for (int c = 0; c < 3; ++c) row[3 * u + c] = rgb[2 - c];  // stored B, G, R
    }
  }
}

RadianceImage CameraRenderer::renderRadiance(const World& world, const SplineTrajectory& trajectory,
                                             const Eigen::Isometry3d& T_body_cam, const Illumination& illumination,
                                             Time t, double exposure_s, bool textureless) const {
  const int samples = config_.motion_blur_samples;
  const double exposure_ns = exposure_s * 1e9;
  std::vector<SubFrame> subframes(static_cast<std::size_t>(samples));
  (void)trajectory.pose(t);  // throws std::out_of_range when the frame itself is outside the trajectory
  for (int i = 0; i < samples; ++i) {
    SubFrame& s = subframes[static_cast<std::size_t>(i)];
    const Time offset = static_cast<Time>(std::llround(exposure_ns * ((i + 0.5) / samples - 0.5)));
    s.t = std::clamp(t + offset, trajectory.startTime(), trajectory.endTime());
    const Eigen::Isometry3d T_world_cam = trajectory.pose(s.t) * T_body_cam;
    s.R_world_cam = T_world_cam.linear();
    s.origin_world = T_world_cam.translation();
  }
  RadianceImage image;
  image.width = config_.intrinsics.width;
  image.height = config_.intrinsics.height;
  image.channels = config_.color ? 3 : 1;
  const std::size_t stride = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
  image.grey.resize(stride * static_cast<std::size_t>(image.height));
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v != rows.end(); ++v) 
      renderRow(world, subframes, illumination, v, image.grey.data() + stride * v, textureless);
  });
  return image;
}

CameraFrame CameraRenderer::render(const World& world, const SplineTrajectory& trajectory,
                                   const Eigen::Isometry3d& T_body_cam, const Illumination& illumination, Time t,
                                   std::uint64_t seed, std::uint64_t frame_index, bool textureless) const {
  const RadianceImage radiance =
      renderRadiance(world, trajectory, T_body_cam, illumination, t, config_.exposure_s, textureless);
  CameraFrame frame;
  frame.t = t;
  frame.camera_id = 0;
  frame.source = "sim";
  Image& image = frame.image;
  image.width = radiance.width;
  image.height = radiance.height;
  image.channels = radiance.channels;
  image.data.resize(radiance.grey.size());
  const float sigma = config_.noise ? static_cast<float>(config_.noise_sigma) : 0.0f;
  const detail::GaussianQuantiles& normal = detail::gaussianQuantiles();
  const int channels = radiance.channels;
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v != rows.end(); ++v) {
      for (int u = 0; u < image.width; ++u) {
        const std::uint64_t pixel = static_cast<std::uint64_t>(v) * width_ + static_cast<std::uint64_t>(u);
        // Read noise [grey levels] of channel `lane`; one hash per pixel serves all channels.
        const std::uint64_t hash = sigma > 0.0f ? hashKeys(seed, Stream::kCamera, frame_index, pixel) : 0;
        for (int c = 0; c < channels; ++c) {
          const std::size_t i = pixel * static_cast<std::size_t>(channels) + static_cast<std::size_t>(c);
          const float noise = sigma > 0.0f ? sigma * normal(hash, c) : 0.0f;
          image.data[i] = detail::quantiseGrey(radiance.grey[i] + noise);
        }
      }
    }
  });
  return frame;
}

}  // namespace drover::sim
