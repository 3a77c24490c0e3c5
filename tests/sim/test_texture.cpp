// Procedural textures: kWhite is flat, every textured kind has strong gradients at camera scale, patterns are
// deterministic and change with the seed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sim/texture.hpp"

namespace drover::sim {
namespace {

const std::vector<Texture> kTextured = {Texture::kNoise,   Texture::kBrick,   Texture::kStraw,   Texture::kFence,
                                        Texture::kPen,     Texture::kConcrete, Texture::kAsphalt, Texture::kGrass,
                                        Texture::kFoliage, Texture::kBark,    Texture::kCarPaint, Texture::kMetal};

Material material(Texture t, std::uint32_t seed = 1) {
  Material m;
  m.texture = t;
  m.albedo = Eigen::Vector3f(0.6f, 0.55f, 0.5f);
  m.seed = seed;
  return m;
}

float luminance(const Eigen::Vector3f& c) { return 0.299f * c.x() + 0.587f * c.y() + 0.114f * c.z(); }

// Mean |grad luminance| [1/m] by finite differences on a 0.01 m grid over a 2 m x 2 m patch away from the origin.
double materialGradient(const Material& m) {
  constexpr double h = 0.01;
  constexpr int n = 200;
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d uv(13.0 + i * h, -7.0 + j * h);
      const float c = luminance(shade(m, uv));
      const float du = luminance(shade(m, uv + Eigen::Vector2d(h, 0))) - c;
      const float dv = luminance(shade(m, uv + Eigen::Vector2d(0, h))) - c;
      sum += std::hypot(du, dv) / h;
    }
  }
  return sum / (n * n);
}

std::string name(Texture t) { return std::to_string(static_cast<int>(t)); }

TEST(Texture, WhiteIsExactlyTheAlbedoEverywhere) {
  const Material m = material(Texture::kWhite);
  for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.37, -12.5), Eigen::Vector2d(1e3, 4e2)}) {
    EXPECT_EQ(shade(m, uv), m.albedo);
  }
  EXPECT_EQ(materialGradient(m), 0.0);
}

TEST(Texture, EveryTexturedKindHasStrongGradientsAtCameraScale) {
  // 2 / m of luminance: at 5 m and 460 px focal length (1.1 cm per pixel) that is ~5 grey levels per pixel.
  for (const Texture t : kTextured) {
    const double g = materialGradient(material(t));
    EXPECT_GT(g, 2.0) << "texture " << name(t);
    EXPECT_TRUE(std::isfinite(g)) << "texture " << name(t);
  }
}

TEST(Texture, ColoursStayInUnitRange) {
  for (const Texture t : kTextured) {
    Material m = material(t);
    m.albedo = Eigen::Vector3f::Constant(1.0f);
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector3f c = shade(m, Eigen::Vector2d(i * 0.0173, i * -0.0291));
      ASSERT_TRUE((c.array() >= 0.0f).all() && (c.array() <= 1.0f).all()) << "texture " << name(t);
    }
  }
}

TEST(Texture, SameInputsGiveTheSameColour) {
  for (const Texture t : kTextured) {
    const Material a = material(t, 5), b = material(t, 5);
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector2d uv(i * 0.031, 100.0 - i * 0.017);
      ASSERT_EQ(shade(a, uv), shade(b, uv)) << "texture " << name(t);
    }
  }
}

TEST(Texture, DifferentSeedsGiveDifferentPatterns) {
  for (const Texture t : kTextured) {
    const Material a = material(t, 1), b = material(t, 2);
    int differing = 0;
    constexpr int n = 400;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d uv(0.5 + i * 0.047, 0.3 + i * 0.029);
      differing += (shade(a, uv) - shade(b, uv)).norm() > 1e-3f;
    }
    EXPECT_GT(differing, n / 4) << "texture " << name(t);
  }
}

TEST(Texture, ScaleStretchesThePattern) {
  // A pattern at scale 2 sampled at 2 uv equals the pattern at scale 1 sampled at uv (features scale with it).
  for (const Texture t : kTextured) {
    Material small = material(t), big = material(t);
    big.scale = 2.0f;
    for (int i = 0; i < 100; ++i) {
      const Eigen::Vector2d uv(0.123 + i * 0.037, 0.456 + i * 0.051);
      EXPECT_LT((shade(small, uv) - shade(big, 2.0 * uv)).norm(), 1e-4f) << "texture " << name(t);
    }
  }
}

}  // namespace
}  // namespace drover::sim
