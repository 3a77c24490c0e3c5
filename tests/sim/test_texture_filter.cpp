// Filtered textures (sim/texture.hpp's footprint, CameraModelConfig::texture_filter): a footprint wider than every
// pattern gives the pattern's mean over the surface, one that spans a few cells averages away the cells, and a
// camera that filters its textures sees a far, finely textured wall with one ray a pixel much as with 4 x 4 rays a
// pixel, where without the filter one ray a pixel aliases.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/camera_model.hpp"
#include "sim/texture.hpp"
#include "support/camera_scene.hpp"

namespace drover::sim {
namespace {

const std::vector<Texture> kFilteredKinds = {
    Texture::kNoise,   Texture::kBrick,   Texture::kStraw,   Texture::kFence,   Texture::kPen,      Texture::kConcrete,
    Texture::kAsphalt, Texture::kGrass,   Texture::kFoliage, Texture::kBark,    Texture::kCarPaint, Texture::kMetal};

Material filterMaterial(Texture t) {
  Material m;
  m.texture = t;
  m.albedo = Eigen::Vector3f(0.6f, 0.55f, 0.5f);
  m.seed = 3;
  return m;
}

float filterLuma(const Eigen::Vector3f& c) { return 0.299f * c.x() + 0.587f * c.y() + 0.114f * c.z(); }

// Mean luminance of the point values over a side x side m square at `corner`, on an n x n grid.
double pointMean(const Material& m, const Eigen::Vector2d& corner, double side, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) sum += filterLuma(shade(m, corner + Eigen::Vector2d(i + 0.5, j + 0.5) * side / n));
  return sum / (n * n);
}

// At a zero footprint each pattern is its point value as before the filter existed: the sums of 500 luminances per
// kind (in kFilteredKinds' order) below were taken with the renderer's textures of before the footprint (commit
// c0bcab8's texture.cpp), and agree with today's to the float's last digits.
TEST(TextureFilter, AZeroFootprintGivesThePointValuesOfBeforeTheFilter) {
  const double before[] = {258.625796080, 292.453381538, 234.078293011, 118.027833655, 107.194788769, 271.678543031,
                           225.696882844, 244.109540582, 180.022493422, 245.029594854, 235.028932229, 255.890362173};
  for (std::size_t i = 0; i < kFilteredKinds.size(); ++i) {
    const Material m = filterMaterial(kFilteredKinds[i]);
    double sum = 0;
    for (int k = 0; k < 500; ++k) sum += filterLuma(shade(m, Eigen::Vector2d(0.0137 * k - 3.1, 0.0071 * k + 1.3), 0.0));
    EXPECT_NEAR(sum, before[i], 1e-6) << "texture " << static_cast<int>(kFilteredKinds[i]);
  }
}

// With a 20 m footprint every pattern (cells and lines of 1.5 cm to 1.2 m) is below half the footprint: what is left
// is its mean, the same everywhere, and that mean is the one its point values have over a large area. Car paint's
// dirt squared and grass's patches times blades keep the value at the noise's mean, which is off their area mean by
// a few per cent.
TEST(TextureFilter, AFootprintWiderThanEveryPatternGivesThePatternsAreaMean) {
  for (Texture t : kFilteredKinds) {
    const Material m = filterMaterial(t);
    const double area_mean = pointMean(m, Eigen::Vector2d(20.0, -10.0), 12.0, 600);
    double lo = 1e9, hi = -1e9;
    for (int k = 0; k < 50; ++k) {
      const double v = filterLuma(shade(m, Eigen::Vector2d(20.0 + 0.23 * k, -10.0 + 0.19 * k), 20.0));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    const bool nonlinear = t == Texture::kCarPaint || t == Texture::kGrass;
    // What varies is the fence's posts and the pens' bars: 20 m is not a whole number of all their periods.
    EXPECT_LT(hi - lo, 0.02 * area_mean) << "texture " << static_cast<int>(t) << ": filtered values vary";
    EXPECT_NEAR(0.5 * (lo + hi), area_mean, (nonlinear ? 0.09 : 0.03) * area_mean)
        << "texture " << static_cast<int>(t);
  }
}

// Per axis the weight a footprint of r cells gives a cell's noise is the least-squares prediction of the noise's box
// average from its centre value: measured here on kNoise (0.15 m cells, 3 octaves) against box averages of 24 x 24
// point values, the filtered value beats the point value as that prediction for footprints of half a cell to two.
TEST(TextureFilter, TheFilteredValuePredictsTheFootprintsBoxAverageBetterThanThePointValue) {
  const Material m = filterMaterial(Texture::kNoise);
  for (double footprint : {0.04, 0.08, 0.15, 0.3}) {
    double filtered_error = 0, point_error = 0;
    for (int k = 0; k < 400; ++k) {
      const Eigen::Vector2d centre(5.0 + 0.311 * k, 2.0 + 0.173 * k);
      const double box = pointMean(m, centre - Eigen::Vector2d::Constant(footprint / 2), footprint, 24);
      filtered_error += std::pow(filterLuma(shade(m, centre, footprint)) - box, 2);
      point_error += std::pow(filterLuma(shade(m, centre)) - box, 2);
    }
    EXPECT_LT(filtered_error, 0.8 * point_error) << "footprint " << footprint << " m";
  }
}

// Mean |a - b| over two mono images [grey levels].
double meanAbsoluteDifference(const Image& a, const Image& b) {
  double sum = 0;
  for (std::size_t i = 0; i < a.data.size(); ++i) sum += std::abs(a.data[i] - b.data[i]);
  return sum / static_cast<double>(a.data.size());
}

TEST(TextureFilter, AFarMetalWallWithOneRayAPixelLooksAsWithSixteenOnlyWhenFiltered) {
  Material roof = filterMaterial(Texture::kMetal);  // brushed streaks of 4 and 2 cm, seams of 2 cm
  const World world = test::wallWorld(12.0, roof);  // 2.6 cm a pixel at 12 m
  std::vector<PathSample> still(5);
  for (int i = 0; i < 5; ++i) still[static_cast<std::size_t>(i)].t = i * kNanosPerSecond / 4;
  const SplineTrajectory trajectory(still);
  const auto render = [&](int rays, bool filter) {
    CameraModelConfig config;
    config.noise = false;
    config.pixel_samples = rays;
    config.texture_filter = filter;
    return CameraRenderer(config).render(world, trajectory, test::forwardCamera(), {}, kNanosPerSecond / 2, 1, 0);
  };
  const Image reference = render(4, false).image;
  const double aliased = meanAbsoluteDifference(render(1, false).image, reference);
  const double filtered = meanAbsoluteDifference(render(1, true).image, reference);
  std::printf("far metal wall against 4x4 rays: one ray %.2f grey levels, one ray filtered %.2f\n", aliased, filtered);
  EXPECT_GT(aliased, 3.0) << "the wall must alias with one ray a pixel for this to test anything";
  EXPECT_LT(filtered, 0.5 * aliased);
  // At 4 x 4 rays the filter changes little: the rays already average most of the streaks.
  EXPECT_LT(meanAbsoluteDifference(render(4, true).image, reference), 0.5 * filtered);
}

}  // namespace
}  // namespace drover::sim
