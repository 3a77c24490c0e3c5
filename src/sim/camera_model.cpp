// Camera model configuration, per-pixel ray precomputation and projection helpers. Rendering: camera_render.cpp.
#include "sim/camera_model.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace drover::sim {

namespace {

// Undistortion tolerance: 1e-10 px, expressed in normalised units (divide by the larger focal length).
double undistortTolerance(const CameraIntrinsics& k) { return 1e-10 / std::max(k.fx, k.fy); }

std::string validateIntrinsics(const CameraIntrinsics& k) {
  std::ostringstream error;
  if (k.width <= 0 || k.height <= 0) {
    error << "camera image size must be positive, got " << k.width << "x" << k.height;
  } else if (!(k.fx > 0) || !(k.fy > 0) || !std::isfinite(k.fx) || !std::isfinite(k.fy)) {
    error << "camera focal lengths must be positive and finite, got fx = " << k.fx << ", fy = " << k.fy;
  } else if (!std::isfinite(k.cx) || !std::isfinite(k.cy)) {
    error << "camera principal point must be finite, got (" << k.cx << ", " << k.cy << ")";
  } else if (k.distortion == DistortionModel::kEquidistant) {
    error << "camera distortion model equidistant is not supported by the simulator (use radial-tangential)";
  } else if (k.distortion == DistortionModel::kRadialTangential &&
             k.distortion_coeffs.size() != 4 && k.distortion_coeffs.size() != 5) {
    error << "radial-tangential distortion needs 4 or 5 coefficients (k1 k2 p1 p2 [k3]), got "
          << k.distortion_coeffs.size();
  } else {
    for (double c : k.distortion_coeffs) {
      if (!std::isfinite(c)) error << "camera distortion coefficient is not finite: " << c;
    }
  }
  return error.str();
}

}  // namespace

CameraIntrinsics CameraModelConfig::defaultIntrinsics() {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 460.0;
  k.cx = 319.5;
  k.cy = 239.5;
  k.distortion = DistortionModel::kRadialTangential;
  k.distortion_coeffs = {-0.28, 0.07, 2e-4, -1e-4};
  return k;
}

std::string CameraModelConfig::validate() const {
  if (std::string e = validateIntrinsics(intrinsics); !e.empty()) return e;
  std::ostringstream error;
  if (!(rate_hz > 0) || !std::isfinite(rate_hz)) {
    error << "camera rate_hz must be positive, got " << rate_hz;
  } else if (!(exposure_s >= 0) || !(exposure_s < 1.0 / rate_hz)) {
    error << "camera exposure_s must be in [0, 1 / rate_hz = " << 1.0 / rate_hz << "), got " << exposure_s;
  } else if (motion_blur_samples < 1 || motion_blur_samples > 64) {
    error << "camera motion_blur_samples must be in [1, 64], got " << motion_blur_samples;
  } else if (pixel_samples < 1 || pixel_samples > 4) {
    error << "camera pixel_samples must be in [1, 4], got " << pixel_samples;
  } else if (edge_pixel_samples != 0 &&
             (pixel_samples < 2 || edge_pixel_samples <= pixel_samples || edge_pixel_samples > 4)) {
    error << "camera edge_pixel_samples must be 0 (off) or in (pixel_samples, 4] with pixel_samples >= 2, got "
          << edge_pixel_samples << " with pixel_samples " << pixel_samples;
  } else if (!(noise_sigma >= 0) || !std::isfinite(noise_sigma)) {
    error << "camera noise_sigma must be >= 0 and finite, got " << noise_sigma;
  } else if (!sky.allFinite() || sky.minCoeff() < 0) {
    error << "camera sky colour must be finite and >= 0, got (" << sky.transpose() << ")";
  } else if (std::string e = exposure.validate(); !e.empty()) {
    error << e;
  }
  return error.str();
}

CameraRenderer::CameraRenderer(const CameraModelConfig& config) : config_(config) {
  if (std::string e = config_.validate(); !e.empty()) throw std::invalid_argument("CameraModelConfig: " + e);
  const CameraIntrinsics& k = config_.intrinsics;
  width_ = static_cast<std::size_t>(k.width);
  rays_cam_.resize(width_ * static_cast<std::size_t>(k.height));
  tbb::parallel_for(tbb::blocked_range<int>(0, k.height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v != rows.end(); ++v) {
      for (int u = 0; u < k.width; ++u) {
        rays_cam_[static_cast<std::size_t>(v) * width_ + u] = unproject(Eigen::Vector2d(u, v)).cast<float>();
      }
    }
  });
  if (config_.pixel_samples > 1) rays_area_ = areaRays(config_.pixel_samples);
  if (config_.edge_pixel_samples > 0) rays_edge_ = areaRays(config_.edge_pixel_samples);
  // The field of view the image covers, in |xn|^2, from the rays through the image border (with margin).
  double max_r2 = 0;
  for (const Eigen::Vector3f& r : rays_cam_) {
    max_r2 = std::max(max_r2, (static_cast<double>(r.x()) * r.x() + static_cast<double>(r.y()) * r.y()) /
                                  (static_cast<double>(r.z()) * r.z()));
  }
  max_r2_ = 1.2 * max_r2;
}

std::vector<Eigen::Vector3f> CameraRenderer::areaRays(int n) const {
  const CameraIntrinsics& k = config_.intrinsics;
  const std::size_t per_pixel = static_cast<std::size_t>(n) * static_cast<std::size_t>(n);
  std::vector<Eigen::Vector3f> rays(width_ * static_cast<std::size_t>(k.height) * per_pixel);
  tbb::parallel_for(tbb::blocked_range<int>(0, k.height), [&](const tbb::blocked_range<int>& rows) {
    for (int v = rows.begin(); v != rows.end(); ++v) {
      for (int u = 0; u < k.width; ++u) {
        Eigen::Vector3f* out = &rays[(static_cast<std::size_t>(v) * width_ + u) * per_pixel];
        for (int b = 0; b < n; ++b)
          for (int a = 0; a < n; ++a)
            *out++ = unproject(Eigen::Vector2d(u + (a + 0.5) / n - 0.5, v + (b + 0.5) / n - 0.5)).cast<float>();
      }
    }
  });
  return rays;
}

Eigen::Vector3d CameraRenderer::unproject(const Eigen::Vector2d& pixel) const {
  const CameraIntrinsics& k = config_.intrinsics;
  const Eigen::Vector2d xd((pixel.x() - k.cx) / k.fx, (pixel.y() - k.cy) / k.fy);
  const std::optional<Eigen::Vector2d> xn = undistortNormalized(k, xd, undistortTolerance(k));
  if (!xn) {
    std::ostringstream error;
    error << "camera distortion cannot be inverted at pixel (" << pixel.x() << ", " << pixel.y() << ")";
    throw std::invalid_argument(error.str());
  }
  return Eigen::Vector3d(xn->x(), xn->y(), 1.0).normalized();
}

std::optional<Eigen::Vector2d> CameraRenderer::project(const Eigen::Vector3d& p_cam) const {
  if (!(p_cam.z() > 1e-9)) return std::nullopt;
  const Eigen::Vector2d xn = p_cam.head<2>() / p_cam.z();
  if (!(xn.squaredNorm() <= max_r2_)) return std::nullopt;  // beyond the image's field of view (model may fold)
  const CameraIntrinsics& k = config_.intrinsics;
  const Eigen::Vector2d xd = distortNormalized(k, xn);
  const Eigen::Vector2d pixel(k.fx * xd.x() + k.cx, k.fy * xd.y() + k.cy);
  if (pixel.x() < -0.5 || pixel.y() < -0.5 || pixel.x() > k.width - 0.5 || pixel.y() > k.height - 0.5) {
    return std::nullopt;
  }
  return pixel;
}

}  // namespace drover::sim
