// The simulated camera's sensor and auto exposure (src/sim/camera_exposure.hpp, camera_stream.hpp): known answers
// on a uniform white wall, whose every pixel sees the same radiance, so the image mean is the model's mean and the
// image's spread is the model's temporal noise.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "sim/camera_exposure.hpp"
#include "sim/camera_stream.hpp"
#include "support/camera_scene.hpp"

using namespace drover;
using namespace drover::sim;

namespace {

constexpr Time kSecond = kNanosPerSecond;
constexpr float kAlbedo = 0.6f;

using drover::test::forwardCamera;

// At the origin over [0, 10] s.
SplineTrajectory stillTrajectory() {
  std::vector<PathSample> samples;
  for (int i = 0; i <= 10; ++i) {
    PathSample s;
    s.t = i * kSecond;
    samples.push_back(s);
  }
  return SplineTrajectory(samples);
}

// A 40 m x 40 m white wall 3 m ahead (normal -x): it fills the view.
World whiteWall() {
  Rectangle wall;
  wall.T_world_rect.linear().col(0) = Eigen::Vector3d(0, -1, 0);
  wall.T_world_rect.linear().col(1) = Eigen::Vector3d(0, 0, 1);
  wall.T_world_rect.linear().col(2) = Eigen::Vector3d(-1, 0, 0);
  wall.T_world_rect.translation() = Eigen::Vector3d(3, 0, 0);
  wall.half_size = Eigen::Vector2d(20, 20);
  Material m;
  m.texture = Texture::kWhite;
  m.albedo = Eigen::Vector3f::Constant(kAlbedo);
  World world;
  world.addRectangle(wall, m);
  world.build();
  return world;
}

// The wall's ideal grey (255 * value) under scene light `light`.
double wallIdeal(float light) { return 255.0 * kAlbedo * light * lambertFactor(Eigen::Vector3d(-1, 0, 0)); }

// 160 x 120 pinhole, no distortion: 19200 pixels per frame.
CameraModelConfig smallCamera() {
  CameraModelConfig c;
  CameraIntrinsics& k = c.intrinsics;
  k.width = 160, k.height = 120, k.fx = k.fy = 115.0, k.cx = 79.5, k.cy = 59.5;
  k.distortion = DistortionModel::kNone;
  k.distortion_coeffs.clear();
  c.rate_hz = 15;
  return c;
}

Illumination constantLight(float light) {
  return [light](Time, const Eigen::Vector3d&) { return light; };
}

struct Moments {
  double mean = 0, std = 0;
};
Moments moments(const Image& image) {
  Moments m;
  m.mean = meanGrey(image);
  double variance = 0;
  for (std::uint8_t p : image.data) variance += (p - m.mean) * (p - m.mean);
  m.std = std::sqrt(variance / static_cast<double>(image.data.size()));
  return m;
}

TEST(CameraExposureConfig, ValidateNamesTheBadValue) {
  EXPECT_EQ(CameraExposureConfig{}.validate(), "");
  const auto error = [](auto change) {
    CameraExposureConfig c;
    change(c);
    return c.validate();
  };
  EXPECT_NE(error([](auto& c) { c.full_well_e = 0; }).find("full_well_e"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.read_noise_e = -1; }).find("read_noise_e"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.white_rate_e_per_s = NAN; }).find("white_rate_e_per_s"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.min_exposure_s = 0.1; }).find("min_exposure_s"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.max_gain = 0.5; }).find("max_gain"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.fixed_gain = 32; }).find("fixed_gain"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.target_grey = 255; }).find("target_grey"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.damping = 0; }).find("damping"), std::string::npos);
  EXPECT_NE(error([](auto& c) { c.max_step = 1; }).find("max_step"), std::string::npos);
  CameraModelConfig camera;
  camera.exposure.deadband = 1;
  EXPECT_NE(camera.validate().find("deadband"), std::string::npos) << "the camera's validate() covers its exposure";
}

TEST(AutoExposure, SpendsExposureBeforeGainWithinTheLimits) {
  const CameraExposureConfig c;  // 20 us .. 20 ms, gain 1 .. 16
  const AutoExposure ae(c, 0.01, 15);
  EXPECT_DOUBLE_EQ(ae.split(0.005).exposure_s, 0.005);
  EXPECT_DOUBLE_EQ(ae.split(0.005).gain, 1.0);
  EXPECT_DOUBLE_EQ(ae.split(0.08).exposure_s, 0.02);
  EXPECT_DOUBLE_EQ(ae.split(0.08).gain, 4.0);
  EXPECT_DOUBLE_EQ(ae.split(10.0).gain, 16.0);      // gain runs out
  EXPECT_DOUBLE_EQ(ae.split(1e-9).exposure_s, 20e-6);  // shortest exposure
  // At 60 Hz the exposure must end before the next frame: 0.9 / 60 s.
  EXPECT_DOUBLE_EQ(AutoExposure(c, 0.01, 60).split(0.02).exposure_s, 0.015);
}

TEST(AutoExposure, BrightSceneConvergesToTheTargetMeanWithinTwelveFrames) {
  // Daylight, starting at 10 ms: 10x too long, the wall saturates (255). The controller steps down by
  // (target / mean)^0.6 a frame; after 12 frames the mean is within the deadband (5 %) plus noise of the target.
  const CameraModelConfig config = smallCamera();
  const CameraRenderer renderer(config);
  const RadianceImage radiance =
      renderer.renderRadiance(whiteWall(), stillTrajectory(), forwardCamera(), constantLight(1.0f), kSecond, 0.01);
  const CameraSensor sensor(config.exposure, true);
  AutoExposure ae(config.exposure, 0.01, config.rate_hz);
  std::vector<double> means;
  for (int k = 0; k < 12; ++k) {
    means.push_back(meanGrey(sensor.expose(radiance, ae.current(), 1, static_cast<std::uint64_t>(k))));
    ae.update(means.back());
  }
  EXPECT_GT(means.front(), 254.5) << "the first frame is saturated (read noise takes a few pixels to 254)";
  EXPECT_NEAR(means.back(), config.exposure.target_grey, 0.06 * config.exposure.target_grey)
      << means[6] << " " << means[8] << " " << means[10];
  EXPECT_DOUBLE_EQ(ae.current().gain, 1.0) << "daylight needs no gain";
  // The exposure the model predicts for the target: target * K / (value * white_rate).
  const double expected_s = config.exposure.target_grey * (config.exposure.full_well_e / 255.0) /
                            (wallIdeal(1.0f) / 255.0 * config.exposure.white_rate_e_per_s);
  EXPECT_NEAR(ae.current().exposure_s, expected_s, 0.06 * expected_s);
}

TEST(CameraStream, FirstFrameIsAlreadySettledOnItsScene) {
  CameraStream camera(smallCamera());
  const Image image =
      camera.next(whiteWall(), stillTrajectory(), forwardCamera(), constantLight(0.3f), kSecond, 1, 0).image;
  EXPECT_NEAR(meanGrey(image), 100.0, 6.0);
  EXPECT_FALSE(camera.lastAtFloor());
}

// At a night light level the exposure and gain run out: the mean falls below the target and the noise is the
// sensor's prediction (shot + read noise amplified by 16x gain, 8-bit rounding), for a count below and above the
// exact-Poisson limit (32 e-).
TEST(CameraStream, AtTheFloorTheImageIsDarkerThanTheTargetAndItsNoiseMatchesTheModel) {
  const CameraModelConfig config = smallCamera();
  for (const float light : {2e-4f, 6e-4f}) {
    CameraStream camera(config);
    Moments last;
    for (std::uint64_t k = 0; k < 5; ++k)
      last = moments(camera.next(whiteWall(), stillTrajectory(), forwardCamera(), constantLight(light),
                                 kSecond + static_cast<Time>(k) * kSecond / 15, 7, k)
                         .image);
    ASSERT_TRUE(camera.lastAtFloor()) << light;
    const ExposureSetting& s = camera.lastSetting();
    EXPECT_DOUBLE_EQ(s.exposure_s, config.exposure.max_exposure_s);
    EXPECT_DOUBLE_EQ(s.gain, config.exposure.max_gain);
    const CameraSensor sensor(config.exposure, true);
    const double ideal = wallIdeal(light);
    EXPECT_LT(last.mean, 0.5 * config.exposure.target_grey) << light;
    EXPECT_NEAR(last.mean, sensor.meanGrey(ideal, s), 0.03 * sensor.meanGrey(ideal, s)) << light;
    EXPECT_NEAR(last.std, sensor.noiseGrey(ideal, s), 0.10 * sensor.noiseGrey(ideal, s))
        << light << ": " << sensor.electrons(ideal, s) << " e-";
    // The noise is mostly shot noise at this level, not a fixed read noise: it is far above 2 grey levels.
    EXPECT_GT(last.std, 3.0) << light;
  }
}

TEST(CameraSensor, WithoutNoiseItReadsTheMeanAndSaturatesAtTheFullWell) {
  CameraModelConfig config = smallCamera();
  const CameraSensor sensor(config.exposure, false);
  RadianceImage radiance;
  radiance.width = 3, radiance.height = 1, radiance.channels = 1;
  radiance.grey = {0.0f, 100.0f, 1000.0f};
  const ExposureSetting s{0.001, 2.0};
  const Image image = sensor.expose(radiance, s, 1, 0);
  // 100 / 255 * 1e7 e-/s * 1 ms = 3922 e-; * 2 / (6000 / 255) = 333 -> 255. Halve the exposure time: 166.6.
  EXPECT_EQ(image.data[0], 0);
  EXPECT_EQ(image.data[1], 255);
  EXPECT_EQ(image.data[2], 255);
  EXPECT_NEAR(sensor.meanGrey(100.0, {0.0005, 2.0}), 100.0 / 255.0 * 1e7 * 0.0005 * 2.0 * 255.0 / 6000.0, 1e-9);
  EXPECT_EQ(sensor.expose(radiance, {0.0005, 2.0}, 1, 0).data[1], 167);
}

TEST(CameraStream, SameSeedGivesIdenticalImagesForAnyThreadCountAndAnotherSeedDoesNot) {
  const World world = whiteWall();
  const SplineTrajectory path = stillTrajectory();
  const auto frames = [&](std::uint64_t seed) {
    CameraStream camera(smallCamera());
    std::vector<std::vector<std::uint8_t>> out;
    for (std::uint64_t k = 0; k < 3; ++k)
      out.push_back(camera.next(world, path, forwardCamera(), constantLight(1e-3f),
                                kSecond + static_cast<Time>(k) * kSecond / 15, seed, k)
                        .image.data);
    return out;
  };
  std::vector<std::vector<std::uint8_t>> one_thread;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = frames(42);
  }
  EXPECT_TRUE(frames(42) == one_thread);
  const auto other = frames(43);
  EXPECT_FALSE(other[0] == one_thread[0]);
  EXPECT_FALSE(one_thread[1] == one_thread[0]) << "the noise changes from frame to frame";
}

}  // namespace
