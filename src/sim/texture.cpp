// Procedural textures. Every pattern is a pure function of (uv, material.seed, material.scale): value noise on an
// integer lattice hashed with mix64 (random.hpp), plus periodic structures (bricks, posts, bars). Convention: u runs
// horizontally and v up on vertical surfaces (see World::intersect), which bricks, fences and pens rely on.
// Feature sizes are 0.03-1.2 m times material.scale so images have strong gradients at 1-10 m viewing distance.
#include "sim/texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "sim/random.hpp"

namespace drover::sim {
namespace {

using Eigen::Vector3f;

// Lattice cell value in [0, 1): one mix64 of (layer key, ix, iy).
inline float cellValue(std::uint64_t key, std::int64_t ix, std::int64_t iy) {
  const std::uint64_t h = mix64(key ^ (static_cast<std::uint64_t>(ix) * 0x9E3779B97F4A7C15ULL) ^
                                (static_cast<std::uint64_t>(iy) * 0xC2B2AE3D27D4EB4FULL));
  return static_cast<float>(h >> 40) * 0x1.0p-24f;
}

// Bilinear value noise with smoothstep weights, in [0, 1); x, y in lattice cells.
float valueNoise(std::uint64_t key, double x, double y) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  const float tx = static_cast<float>(x - fx), ty = static_cast<float>(y - fy);
  const float sx = tx * tx * (3.0f - 2.0f * tx), sy = ty * ty * (3.0f - 2.0f * ty);
  const float v00 = cellValue(key, ix, iy), v10 = cellValue(key, ix + 1, iy);
  const float v01 = cellValue(key, ix, iy + 1), v11 = cellValue(key, ix + 1, iy + 1);
  const float a = v00 + sx * (v10 - v00), b = v01 + sx * (v11 - v01);
  return a + sy * (b - a);
}

// Fractal sum of `octaves` value-noise layers (cell sizes cell_u, cell_v halving per octave), in [0, 1).
float fbm(std::uint64_t key, const Eigen::Vector2d& uv, double cell_u, double cell_v, int octaves) {
  float sum = 0.0f, norm = 0.0f, amp = 1.0f;
  double fu = 1.0 / cell_u, fv = 1.0 / cell_v;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * valueNoise(key + static_cast<std::uint64_t>(o) * 0x632BE59BD9B4E019ULL, uv.x() * fu, uv.y() * fv);
    norm += amp;
    amp *= 0.5f;
    fu *= 2.0;
    fv *= 2.0;
  }
  return sum / norm;
}

// Position within a period: returns x mod period in [0, period) and the period index.
inline double wrap(double x, double period, std::int64_t& index) {
  const double k = std::floor(x / period);
  index = static_cast<std::int64_t>(k);
  return x - k * period;
}

Vector3f brick(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s) {
  const double h = 0.075 * s, w = 0.225 * s, mortar = 0.015 * s;
  std::int64_t row = 0, col = 0;
  const double fv = wrap(uv.y(), h, row);
  const double fu = wrap(uv.x() + ((row & 1) != 0 ? 0.5 * w : 0.0), w, col);
  const float grain = valueNoise(key + 1, uv.x() / (0.03 * s), uv.y() / (0.03 * s));
  if (fu < mortar || fv < mortar) return Vector3f(0.75f, 0.73f, 0.70f) * (0.85f + 0.3f * grain);
  const float tint = 0.6f + 0.7f * cellValue(key, col, row);
  return m.albedo * tint * (0.85f + 0.3f * grain);
}

Vector3f fence(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s) {
  std::int64_t post = 0, rail = 0;
  const bool on_post = wrap(uv.x(), 1.2 * s, post) < 0.12 * s;
  const bool on_rail = wrap(uv.y(), 0.4 * s, rail) < 0.08 * s;
  if (on_post) return m.albedo * (0.7f + 0.6f * fbm(key, uv, 0.04 * s, 0.4 * s, 2));  // vertical grain
  if (on_rail) return m.albedo * (0.7f + 0.6f * fbm(key + 7, uv, 0.4 * s, 0.04 * s, 2));  // horizontal grain
  return m.albedo * (0.12f + 0.15f * fbm(key + 13, uv, 0.2 * s, 0.2 * s, 2));  // dark gap behind the fence
}

Vector3f pen(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s) {
  std::int64_t bar = 0, rail = 0;
  const double bar_w = 0.04 * s, rail_w = 0.05 * s;
  const double fu = wrap(uv.x(), 0.15 * s, bar), fv = wrap(uv.y(), 0.5 * s, rail);
  const float dirt = fbm(key, uv, 0.1 * s, 0.1 * s, 2);
  if (fu < bar_w) {  // round bar: a highlight across its width
    const float c = static_cast<float>(std::sin(std::numbers::pi * fu / bar_w));
    return m.albedo * (0.4f + 0.7f * c) * (0.8f + 0.3f * dirt);
  }
  if (fv < rail_w) {
    const float c = static_cast<float>(std::sin(std::numbers::pi * fv / rail_w));
    return m.albedo * (0.4f + 0.7f * c) * (0.8f + 0.3f * dirt);
  }
  return m.albedo * (0.1f + 0.15f * dirt);  // the darker pen interior seen between bars
}

Vector3f carPaint(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s) {
  std::int64_t i = 0, j = 0;
  const bool seam = wrap(uv.x(), 0.6 * s, i) < 0.015 * s || wrap(uv.y(), 0.4 * s, j) < 0.015 * s;
  const float dirt = fbm(key, uv, 0.08 * s, 0.08 * s, 3);
  const float shade = 0.75f + 0.5f * dirt * dirt;
  return m.albedo * (seam ? 0.3f * shade : shade);
}

Vector3f metal(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s) {
  std::int64_t i = 0, j = 0;
  const double fu = wrap(uv.x(), 1.0 * s, i), fv = wrap(uv.y(), 0.5 * s, j);
  if (fu < 0.02 * s || fv < 0.02 * s) return m.albedo * 0.25f;  // panel seams
  const double ru = fu - 0.06 * s, rv = fv - 0.06 * s;
  if (ru * ru + rv * rv < 0.0004 * s * s) return m.albedo * 1.3f;  // a rivet near each panel corner
  return m.albedo * (0.55f + 0.8f * fbm(key, uv, 0.6 * s, 0.04 * s, 2));  // brushed streaks along u
}

Vector3f clamp01(const Vector3f& c) { return c.cwiseMax(0.0f).cwiseMin(1.0f); }

}  // namespace

Eigen::Vector3f shade(const Material& m, const Eigen::Vector2d& uv) {
  if (m.texture == Texture::kWhite) return m.albedo;
  const double s = m.scale;
  const std::uint64_t key = hashKeys(m.seed, Stream::kWorld, static_cast<std::uint64_t>(m.texture));
  switch (m.texture) {
    case Texture::kWhite: return m.albedo;
    case Texture::kNoise: return clamp01(m.albedo * (0.25f + 1.5f * fbm(key, uv, 0.15 * s, 0.15 * s, 3)));
    case Texture::kBrick: return clamp01(brick(m, key, uv, s));
    case Texture::kStraw: {  // streaks 0.3 m long and 0.03 m wide, tinted yellow
      const float n = fbm(key, uv, 0.3 * s, 0.03 * s, 2);
      return clamp01(m.albedo.cwiseProduct(Vector3f(1.0f, 0.88f, 0.5f)) * (0.35f + 1.2f * n));
    }
    case Texture::kFence: return clamp01(fence(m, key, uv, s));
    case Texture::kPen: return clamp01(pen(m, key, uv, s));
    case Texture::kConcrete: {
      const float n = fbm(key, uv, 0.12 * s, 0.12 * s, 3);
      const float speck = valueNoise(key + 99, uv.x() / (0.03 * s), uv.y() / (0.03 * s));
      return clamp01(m.albedo * (0.55f + 0.6f * n + 0.25f * speck));
    }
    case Texture::kAsphalt: {
      const float n = fbm(key, uv, 0.08 * s, 0.08 * s, 2);
      const float grain = valueNoise(key + 99, uv.x() / (0.03 * s), uv.y() / (0.03 * s));
      return clamp01(m.albedo * (0.45f + 0.6f * n + (grain > 0.75f ? 0.6f : 0.0f)));
    }
    case Texture::kGrass: {
      const float blades = fbm(key, uv, 0.05 * s, 0.05 * s, 2);
      const float patch = valueNoise(key + 99, uv.x() / (0.6 * s), uv.y() / (0.6 * s));
      return clamp01(m.albedo.cwiseProduct(Vector3f(1.0f + 0.3f * patch, 1.0f, 1.0f)) * (0.35f + 1.0f * blades) *
                     (0.75f + 0.5f * patch));
    }
    case Texture::kFoliage: {
      const float n = fbm(key, uv, 0.1 * s, 0.1 * s, 3);
      return clamp01(m.albedo * (n < 0.42f ? 0.2f + 0.3f * n : 0.6f + 1.0f * (n - 0.42f)));  // leaves and gaps
    }
    case Texture::kBark: return clamp01(m.albedo * (0.3f + 1.1f * fbm(key, uv, 0.04 * s, 0.4 * s, 3)));
    case Texture::kCarPaint: return clamp01(carPaint(m, key, uv, s));
    case Texture::kMetal: return clamp01(metal(m, key, uv, s));
  }
  return m.albedo;
}

}  // namespace drover::sim
