#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <stdexcept>

#include "sim/camera_model.hpp"
#include "support/camera_scene.hpp"

using namespace drover;
using namespace drover::sim;

namespace {

using drover::test::forwardCamera;
using drover::test::wallWorld;

constexpr Time kCameraSecond = kNanosPerSecond;

// Samples every 0.1 s over [0, 1] s at the origin, yaw = yaw_rate * (t - 0.5 s) (looking along +x at 0.5 s).
SplineTrajectory yawingTrajectory(double yaw_rate) {
  std::vector<PathSample> samples;
  for (int i = 0; i <= 10; ++i) {
    PathSample s;
    s.t = i * kCameraSecond / 10;
    s.yaw = yaw_rate * (toSeconds(s.t) - 0.5);
    samples.push_back(s);
  }
  return SplineTrajectory(samples);
}

SplineTrajectory stationaryTrajectory() { return yawingTrajectory(0.0); }

Material whiteMaterial(float albedo) {
  Material m;
  m.texture = Texture::kWhite;
  m.albedo = Eigen::Vector3f::Constant(albedo);
  return m;
}

Material noiseMaterial() {
  Material m;
  m.texture = Texture::kNoise;
  m.scale = 0.1f;
  m.seed = 7;
  return m;
}

// A white box centred 5 m ahead; its front face (normal -x) lies at x = 4.5, y in [-0.9, 0.3], z in [-0.2, 0.6].
World whiteBoxAhead() {
  Box box;
  box.T_world_box.translation() = Eigen::Vector3d(5.0, -0.3, 0.2);
  box.half_extents = Eigen::Vector3d(0.5, 0.6, 0.4);
  World world;
  world.addBox(box, whiteMaterial(1.0f));
  world.build();
  return world;
}

CameraModelConfig noiselessConfig() {
  CameraModelConfig config;
  config.noise = false;
  return config;
}

// Mean |I(u+1, v) - I(u, v)| over a mono image [grey levels].
double horizontalGradientEnergy(const Image& image) {
  double sum = 0;
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u + 1 < image.width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * image.width + u;
      sum += std::abs(static_cast<int>(image.data[i + 1]) - static_cast<int>(image.data[i]));
    }
  }
  return sum / (static_cast<double>(image.height) * (image.width - 1));
}

double meanIntensity(const Image& image) {
  double sum = 0;
  for (std::uint8_t p : image.data) sum += p;
  return sum / static_cast<double>(image.data.size());
}

int expectedGrey(float linear) { return static_cast<int>(std::floor(255.0f * linear + 0.5f)); }

// ~300 textured primitives around the camera: ground, boxes, posts, wall panels (a farm-yard stand-in).
World scenarioLikeWorld() {
  World world;
  Material ground;
  ground.texture = Texture::kGrass;
  world.setGround(-0.5, ground);
  const Texture textures[] = {Texture::kBrick, Texture::kStraw, Texture::kConcrete, Texture::kBark, Texture::kNoise};
  for (int i = 0; i < 100; ++i) {
    const double angle = i * 0.37, radius = 4.0 + (i % 17);
    const auto around = [&](double r, double a) { return Eigen::Vector3d(r * std::cos(a), r * std::sin(a), 0.0); };
    Material m;
    m.texture = textures[i % 5];
    m.seed = static_cast<std::uint32_t>(i);
    Box box;
    box.T_world_box.translation() = around(radius, angle) + Eigen::Vector3d(0, 0, 0.3);
    box.half_extents = Eigen::Vector3d(0.4 + 0.1 * (i % 3), 0.5, 0.8);
    world.addBox(box, m);
    Cylinder post;
    post.base_center = around(radius + 1.5, angle + 0.1) + Eigen::Vector3d(0, 0, -0.5);
    post.radius = 0.1;
    post.height = 1.5;
    world.addCylinder(post, m);
    Rectangle panel;
    panel.T_world_rect.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                                  Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
    panel.T_world_rect.translation() = around(radius + 3, angle) + Eigen::Vector3d(0, 0, 0.5);
    panel.half_size = Eigen::Vector2d(1.0, 2.0);
    world.addRectangle(panel, m);
  }
  world.build();
  return world;
}

}  // namespace

TEST(CameraModel, DefaultIntrinsicsAreEurocLikeAndValid) {
  const CameraModelConfig config;
  const CameraIntrinsics& k = config.intrinsics;
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  EXPECT_EQ(k.fx, 460.0);
  EXPECT_EQ(k.fy, 460.0);
  EXPECT_EQ(k.cx, 319.5);
  EXPECT_EQ(k.cy, 239.5);
  EXPECT_EQ(k.distortion, DistortionModel::kRadialTangential);
  EXPECT_EQ(k.distortion_coeffs, (std::vector<double>{-0.28, 0.07, 2e-4, -1e-4}));
  EXPECT_EQ(config.validate(), "");
}

TEST(CameraModel, ValidateNamesTheBadValueAndTheRendererRefusesIt) {
  const auto errorOf = [](const std::function<void(CameraModelConfig&)>& change) {
    CameraModelConfig config;
    change(config);
    return config.validate();
  };
  EXPECT_NE(errorOf([](auto& c) { c.intrinsics.fx = 0; }).find("fx = 0"), std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.intrinsics.distortion_coeffs = {0.1, 0.2}; }).find("got 2"), std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.motion_blur_samples = 0; }).find("motion_blur_samples"), std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.exposure_s = 0.1; }).find("exposure_s"), std::string::npos);  // > 1 / 15 s
  EXPECT_NE(errorOf([](auto& c) { c.intrinsics.distortion = DistortionModel::kEquidistant; }).find("equidistant"),
            std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.noise_sigma = -1; }).find("noise_sigma"), std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.pixel_samples = 0; }).find("pixel_samples"), std::string::npos);
  EXPECT_NE(errorOf([](auto& c) { c.pixel_samples = 5; }).find("pixel_samples"), std::string::npos);
  CameraModelConfig config;
  config.intrinsics.fx = 0;
  EXPECT_THROW(CameraRenderer{config}, std::invalid_argument);
}

TEST(CameraModel, DistortionJacobianMatchesCentralDifferences) {
  const CameraIntrinsics k = CameraModelConfig::defaultIntrinsics();
  for (const Eigen::Vector2d& xn : {Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.9, 0.6), Eigen::Vector2d(0, 0)}) {
    Eigen::Matrix2d J;
    distortNormalized(k, xn, &J);
    constexpr double h = 1e-6;
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector2d e = Eigen::Vector2d::Unit(i) * h;
      const Eigen::Vector2d numeric = (distortNormalized(k, xn + e) - distortNormalized(k, xn - e)) / (2 * h);
      EXPECT_LT((J.col(i) - numeric).norm(), 1e-8) << "xn = " << xn.transpose() << ", column " << i;
    }
  }
}

TEST(CameraModel, DistortionPullsImageCornersInwardAsBarrelLens) {
  // k1 < 0: a point at normalised radius 1 lands at radius 1 - 0.28 + 0.07 = 0.79 (tangential terms aside).
  const CameraIntrinsics k = CameraModelConfig::defaultIntrinsics();
  const Eigen::Vector2d xd = distortNormalized(k, Eigen::Vector2d(1.0, 0.0));
  EXPECT_NEAR(xd.x(), 0.79 + (-1e-4) * 3.0, 1e-12);  // + p2 (r2 + 2 x^2)
  EXPECT_NEAR(xd.y(), 2e-4 * 1.0, 1e-12);             // p1 (r2 + 2 y^2)
}

TEST(CameraModel, UndistortionRoundTripsEveryPixelToMicroPixels) {
  const CameraRenderer camera(noiselessConfig());
  const CameraIntrinsics& k = camera.config().intrinsics;
  double worst = 0, worst_ray = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const Eigen::Vector2d pixel(u, v);
      const Eigen::Vector3d ray = camera.unproject(pixel);
      EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
      const std::optional<Eigen::Vector2d> back = camera.project(3.7 * ray);
      ASSERT_TRUE(back.has_value()) << "pixel " << u << ", " << v;
      worst = std::max(worst, (*back - pixel).norm());
      worst_ray = std::max(worst_ray, (camera.ray(u, v).cast<double>() - ray).norm());
    }
  }
  EXPECT_LT(worst, 1e-6);
  EXPECT_LT(worst_ray, 1e-6);  // the precomputed float rays are the same rays
  // The corners are strongly distorted: the corner ray is far from the undistorted pinhole ray.
  const Eigen::Vector3d pinhole = Eigen::Vector3d(-k.cx / k.fx, -k.cy / k.fy, 1.0).normalized();
  EXPECT_GT(std::acos(camera.unproject(Eigen::Vector2d(0, 0)).dot(pinhole)), 0.05);
}

TEST(CameraModel, RayThroughPrincipalPointIsTheOpticalAxis) {
  const CameraRenderer camera(noiselessConfig());
  const Eigen::Vector3d ray = camera.unproject(Eigen::Vector2d(319.5, 239.5));
  EXPECT_LT((ray - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  const std::optional<Eigen::Vector2d> pixel = camera.project(Eigen::Vector3d(0, 0, 5));
  ASSERT_TRUE(pixel.has_value());
  EXPECT_LT((*pixel - Eigen::Vector2d(319.5, 239.5)).norm(), 1e-12);
}

TEST(CameraModel, ProjectRejectsPointsBehindTheCameraOrOutsideTheImage) {
  const CameraRenderer camera(noiselessConfig());
  EXPECT_FALSE(camera.project(Eigen::Vector3d(0, 0, -1)).has_value());
  EXPECT_FALSE(camera.project(Eigen::Vector3d(0.1, 0, 0)).has_value());
  EXPECT_FALSE(camera.project(Eigen::Vector3d(50, 0, 1)).has_value());  // 89 deg off axis
  EXPECT_FALSE(camera.project(Eigen::Vector3d(1.2, 0, 1)).has_value());  // just right of the image
  EXPECT_TRUE(camera.project(Eigen::Vector3d(0.7, 0, 1)).has_value());
}

TEST(CameraRenderer, LambertShadingIsAmbientPlusDiffuseFromTheSun) {
  EXPECT_NEAR(sunDirectionWorld().norm(), 1.0, 1e-15);
  EXPECT_NEAR(std::asin(sunDirectionWorld().z()), std::numbers::pi / 3, 1e-12);  // 60 deg above the horizon
  EXPECT_FLOAT_EQ(lambertFactor(sunDirectionWorld()), 1.0f);
  EXPECT_FLOAT_EQ(lambertFactor(-sunDirectionWorld()), 1.0f);  // both sides of a thin wall
  EXPECT_FLOAT_EQ(lambertFactor(Eigen::Vector3d::UnitZ()), 0.35f + 0.65f * std::sqrt(3.0f) / 2.0f);  // ground
  const Eigen::Vector3d grazing = sunDirectionWorld().cross(Eigen::Vector3d::UnitX()).normalized();
  EXPECT_FLOAT_EQ(lambertFactor(grazing), 0.35f);
}

TEST(CameraRenderer, WhiteBoxAppearsWhereProjectPredictsAndTheRestIsSky) {
  CameraModelConfig config = noiselessConfig();
  config.sky = Eigen::Vector3f::Constant(0.2f);
  const CameraRenderer camera(config);
  const World world = whiteBoxAhead();
  const CameraFrame frame = camera.render(world, stationaryTrajectory(), forwardCamera(), {}, kCameraSecond / 2, 1, 0);
  EXPECT_EQ(frame.t, kCameraSecond / 2);
  EXPECT_EQ(frame.camera_id, 0);
  EXPECT_EQ(frame.source, "sim");
  ASSERT_EQ(frame.image.channels, 1);
  ASSERT_EQ(frame.image.data.size(), 640u * 480u);

  // Front-face corners in the camera frame: x_cam = -y_world, y_cam = -z_world, z_cam = x_world.
  double u_min = 1e9, u_max = -1e9, v_min = 1e9, v_max = -1e9;
  for (double y : {-0.9, 0.3}) {
    for (double z : {-0.2, 0.6}) {
      const std::optional<Eigen::Vector2d> p = camera.project(Eigen::Vector3d(-y, -z, 4.5));
      ASSERT_TRUE(p.has_value());
      u_min = std::min(u_min, p->x()), u_max = std::max(u_max, p->x());
      v_min = std::min(v_min, p->y()), v_max = std::max(v_max, p->y());
    }
  }
  const int box_grey = expectedGrey(lambertFactor(Eigen::Vector3d(-1, 0, 0)));
  const int sky_grey = expectedGrey(0.2f);
  ASSERT_GT(box_grey, sky_grey + 20);
  int seen_u_min = 1 << 20, seen_u_max = -1, seen_v_min = 1 << 20, seen_v_max = -1, others = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int grey = frame.image.data[static_cast<std::size_t>(v) * 640 + u];
      if (grey == box_grey) {
        seen_u_min = std::min(seen_u_min, u), seen_u_max = std::max(seen_u_max, u);
        seen_v_min = std::min(seen_v_min, v), seen_v_max = std::max(seen_v_max, v);
      } else if (grey != sky_grey) {
        ++others;
      }
    }
  }
  EXPECT_EQ(others, 0);  // every pixel is either the box face or sky
  EXPECT_NEAR(seen_u_min, u_min, 1.0);
  EXPECT_NEAR(seen_u_max, u_max, 1.0);
  EXPECT_NEAR(seen_v_min, v_min, 1.0);
  EXPECT_NEAR(seen_v_max, v_max, 1.0);
  // Inside the predicted rectangle (1 px in from its edges) everything is box; outside (1 px out) everything sky.
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int grey = frame.image.data[static_cast<std::size_t>(v) * 640 + u];
      if (u > u_min + 1 && u < u_max - 1 && v > v_min + 1 && v < v_max - 1) {
        ASSERT_EQ(grey, box_grey) << u << "," << v;
      }
      if (u < u_min - 1 || u > u_max + 1 || v < v_min - 1 || v > v_max + 1) {
        ASSERT_EQ(grey, sky_grey) << u << "," << v;
      }
    }
  }
}

// A sensor pixel integrates the light over its area: a pixel that a box's vertical edge crosses reads the share of
// its area on the box. With 4 x 4 rays a pixel that share is known to 1/8 (the rays sit at 1/8, 3/8, ... of the
// pixel); with one ray the pixel is all box or all sky (the first test above), and the edge aliases.
TEST(CameraRenderer, WithFourByFourRaysAPixelOnABoxEdgeReadsTheShareOfItsAreaOnTheBox) {
  CameraModelConfig config = noiselessConfig();
  config.intrinsics.distortion = DistortionModel::kNone;  // straight edges: u of the edge is one number
  config.intrinsics.distortion_coeffs.clear();
  config.sky = Eigen::Vector3f::Constant(0.2f);
  config.pixel_samples = 4;
  const CameraRenderer camera(config);
  // Front face at x = 4.5 m, y in [-0.9, 0.3]: its left edge (y = 0.3, x_cam = -0.3) at u = cx - fx * 0.3 / 4.5.
  const World world = whiteBoxAhead();
  const CameraFrame frame = camera.render(world, stationaryTrajectory(), forwardCamera(), {}, kCameraSecond / 2, 1, 0);
  const double u_edge = config.intrinsics.cx - config.intrinsics.fx * 0.3 / 4.5;
  const double box_grey = 255.0 * lambertFactor(Eigen::Vector3d(-1, 0, 0)), sky_grey = 255.0 * 0.2;
  ASSERT_GT(box_grey, sky_grey + 50);
  int partial = 0;
  for (int v = 230; v < 250; ++v) {  // rows through the face's middle (v of its centre ~ cy + fy * -0.2 / 4.5)
    for (int u = static_cast<int>(std::floor(u_edge)) - 2; u <= static_cast<int>(std::floor(u_edge)) + 2; ++u) {
      const double share = std::clamp(u + 0.5 - u_edge, 0.0, 1.0);
      const double grey = frame.image.data[static_cast<std::size_t>(v) * 640 + u];
      EXPECT_NEAR((grey - sky_grey) / (box_grey - sky_grey), share, 1.0 / 8 + 1.0 / (box_grey - sky_grey))
          << "u " << u << ", v " << v << ", edge at u " << u_edge;
      partial += grey > sky_grey + 1 && grey < box_grey - 1;
    }
  }
  EXPECT_EQ(partial, 20) << "one pixel a row lies partly on the box";
}

TEST(CameraRenderer, TexturedWallHasGradientsWhileAWhiteWallShowsOnlyNoise) {
  CameraModelConfig config;  // noise on, sigma 2 grey levels
  const CameraRenderer camera(config);
  const SplineTrajectory still = stationaryTrajectory();
  const World textured = wallWorld(3.0, noiseMaterial());
  const World white = wallWorld(3.0, whiteMaterial(0.6f));
  const double textured_energy =
      horizontalGradientEnergy(camera.render(textured, still, forwardCamera(), {}, kCameraSecond / 2, 3, 0).image);
  const Image white_image = camera.render(white, still, forwardCamera(), {}, kCameraSecond / 2, 3, 0).image;
  const double white_energy = horizontalGradientEnergy(white_image);
  // The noise is unbiased with standard deviation sqrt(sigma^2 + 1/12) (read noise + rounding).
  const double mean = meanIntensity(white_image), flat = 255.0 * 0.6 * lambertFactor(Eigen::Vector3d(-1, 0, 0));
  double variance = 0;
  for (std::uint8_t p : white_image.data) variance += (p - mean) * (p - mean) / static_cast<double>(640 * 480);
  EXPECT_NEAR(mean, flat, 0.05);
  EXPECT_NEAR(std::sqrt(variance), std::sqrt(4.0 + 1.0 / 12.0), 0.03 * 2.0);
  // Two independent N(0, sigma^2) pixels: E|a - b| = 2 sigma / sqrt(pi) = 2.26 grey levels for sigma = 2.
  const double noise_only = 2.0 * config.noise_sigma / std::sqrt(std::numbers::pi);
  EXPECT_NEAR(white_energy, noise_only, 0.1 * noise_only);
  EXPECT_GT(textured_energy, 3.0 * noise_only) << "white wall " << white_energy;
}

TEST(CameraRenderer, IlluminationScalesIntensityByItsFactor) {
  const CameraRenderer camera(noiselessConfig());
  const World world = wallWorld(3.0, whiteMaterial(0.8f));
  const SplineTrajectory still = stationaryTrajectory();
  const Illumination daylight = [](Time, const Eigen::Vector3d&) { return 1.0f; };
  const Illumination dusk = [](Time, const Eigen::Vector3d&) { return 0.2f; };
  const Image bright = camera.render(world, still, forwardCamera(), daylight, kCameraSecond / 2, 1, 0).image;
  const Image dark = camera.render(world, still, forwardCamera(), dusk, kCameraSecond / 2, 1, 0).image;
  const float lambert = lambertFactor(Eigen::Vector3d(-1, 0, 0));
  EXPECT_NEAR(meanIntensity(bright), expectedGrey(0.8f * lambert), 1e-9);  // every pixel, no clipping
  EXPECT_NEAR(meanIntensity(dark), expectedGrey(0.2f * 0.8f * lambert), 1e-9);
  EXPECT_NEAR(meanIntensity(dark) / meanIntensity(bright), 0.2, 0.01);
}

TEST(CameraRenderer, ColourFramesAreBgrAndMonoFramesAreLuma) {
  Material red = whiteMaterial(0.0f);
  red.albedo = Eigen::Vector3f(0.9f, 0.1f, 0.0f);
  const World world = wallWorld(3.0, red);
  const float lambert = lambertFactor(Eigen::Vector3d(-1, 0, 0));
  CameraModelConfig config = noiselessConfig();
  config.color = true;
  const Image bgr = CameraRenderer(config).render(world, stationaryTrajectory(), forwardCamera(), {}, 0, 1, 0).image;
  ASSERT_EQ(bgr.channels, 3);
  ASSERT_EQ(bgr.data.size(), 640u * 480u * 3u);
  const std::size_t centre = (240u * 640u + 320u) * 3u;
  EXPECT_EQ(bgr.data[centre + 0], expectedGrey(0.0f));
  EXPECT_EQ(bgr.data[centre + 1], expectedGrey(0.1f * lambert));
  EXPECT_EQ(bgr.data[centre + 2], expectedGrey(0.9f * lambert));
  const Image mono = CameraRenderer(noiselessConfig())
                         .render(world, stationaryTrajectory(), forwardCamera(), {}, 0, 1, 0).image;
  EXPECT_EQ(mono.data[240u * 640u + 320u], expectedGrey((0.299f * 0.9f + 0.587f * 0.1f) * lambert));
}

TEST(CameraRenderer, SameSeedGivesIdenticalBytesForAnyThreadCount) {
  CameraModelConfig config;
  config.color = true;
  const CameraRenderer camera(config);
  const World world = scenarioLikeWorld();
  const SplineTrajectory path = yawingTrajectory(0.5);
  const auto render = [&](std::uint64_t seed, std::uint64_t frame_index) {
    return camera.render(world, path, forwardCamera(), {}, kCameraSecond / 2, seed, frame_index).image.data;
  };
  std::vector<std::uint8_t> one_thread, two_threads;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = render(42, 7);
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    two_threads = render(42, 7);
  }
  EXPECT_TRUE(one_thread == two_threads);
  EXPECT_TRUE(render(42, 7) == one_thread);
  // The noise really depends on the seed and on the frame index.
  const auto differing = [](const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) n += a[i] != b[i];
    return static_cast<double>(n) / static_cast<double>(a.size());
  };
  EXPECT_GT(differing(render(43, 7), one_thread), 0.5);
  EXPECT_GT(differing(render(42, 8), one_thread), 0.5);
}

TEST(CameraRenderer, MotionBlurOnAFastYawReducesGradientEnergy) {
  const World world = wallWorld(3.0, noiseMaterial());
  const SplineTrajectory spin = yawingTrajectory(4.0);  // 4 rad/s: 0.08 rad (~37 px) during a 20 ms exposure
  CameraModelConfig config = noiselessConfig();
  config.exposure_s = 0.02;
  const double sharp = horizontalGradientEnergy(
      CameraRenderer(config).render(world, spin, forwardCamera(), {}, kCameraSecond / 2, 1, 0).image);
  config.motion_blur_samples = 16;
  const CameraRenderer blurring(config);
  const double blurred =
      horizontalGradientEnergy(blurring.render(world, spin, forwardCamera(), {}, kCameraSecond / 2, 1, 0).image);
  EXPECT_LT(blurred, 0.6 * sharp) << "sharp " << sharp << ", blurred " << blurred;
  // Without motion, averaging sub-frames changes nothing (up to float rounding of the average).
  const SplineTrajectory still = stationaryTrajectory();
  const Image still_blurred = blurring.render(world, still, forwardCamera(), {}, kCameraSecond / 2, 1, 0).image;
  const CameraRenderer sharp_camera(noiselessConfig());
  const Image still_sharp = sharp_camera.render(world, still, forwardCamera(), {}, kCameraSecond / 2, 1, 0).image;
  int worst = 0;
  for (std::size_t i = 0; i < still_sharp.data.size(); ++i) {
    worst = std::max(worst, std::abs(int{still_sharp.data[i]} - int{still_blurred.data[i]}));
  }
  EXPECT_LE(worst, 1);
}
