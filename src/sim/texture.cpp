// Procedural textures. Every pattern is a pure function of (uv, material.seed, material.scale): value noise on an
// integer lattice hashed with mix64 (random.hpp), plus periodic structures (bricks, posts, bars). Convention: u runs
// horizontally and v up on vertical surfaces (see World::intersect), which bricks, fences and pens rely on.
// Feature sizes are 0.03-1.2 m times material.scale so images have strong gradients at 1-10 m viewing distance.
// Filtering: with a footprint f > 0 (the width of surface one camera ray stands for, texture.hpp) each pattern
// approximates its average over an f-wide box instead of its value at a point: each noise octave keeps the share of
// its deviation from its mean that best predicts that average (axisWeight: all of it for cells much larger than f,
// nothing once f spans many cells), and lines (mortar, seams, bars) become the share of the box they cover
// (box-filtered pulse trains, Apodaca & Gritz, Advanced RenderMan, Sec. 11.4). That is what a sensor pixel
// integrating the light does, and what a few rays a pixel cannot do for 2-4 cm detail seen from 5-15 m (the patterns
// then alias: moire that moves unlike the surface). With f = 0 every pattern is its point value, bit for bit as before
// the footprint existed.
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

// The share of a lattice noise's deviation from its mean that best predicts (least squares) its average over a box
// r cells wide along one axis, from its value at the box's centre: the weight a footprint gives a cell size per axis.
// Monte Carlo over this file's value noise (smoothstep-bilinear, uniform lattice values); per axis, as the 2-D box's
// weight is the product of its two axes' within 2 %. Beyond 4 cells it falls as 1 / r (the box averages ~r
// independent cells an axis, and the centre's own cell is one of them). 1 at r = 0.
float axisWeight(double r) {
  static constexpr double kR[] = {0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0};
  static constexpr double kW[] = {1.0, 0.967, 0.882, 0.760, 0.643, 0.438, 0.339};
  if (r >= 4.0) return static_cast<float>(1.36 / r);
  int k = 0;
  while (kR[k + 1] <= r) ++k;
  return static_cast<float>(kW[k] + (r - kR[k]) / (kR[k + 1] - kR[k]) * (kW[k + 1] - kW[k]));
}

// What a footprint of f [m] keeps of a pattern with cells of cell_u x cell_v [m]: 1 at f = 0 (the point value), the
// least-squares prediction of its box average otherwise, 0 once that is below 1 % (the mean is then as good).
inline float detailWeight(double cell_u, double cell_v, double footprint) {
  if (!(footprint > 0)) return 1.0f;
  const float w = axisWeight(footprint / cell_u) * axisWeight(footprint / cell_v);
  return w < 0.01f ? 0.0f : w;
}
inline float detailWeight(double cell, double footprint) { return detailWeight(cell, cell, footprint); }

// A noise value in [0, 1) (mean 0.5) with its detail weight applied: unchanged at 1, its mean at 0.
inline float fadeToMean(float n, float weight) { return weight == 1.0f ? n : weight * n + (1.0f - weight) * 0.5f; }

// Value noise with square cells of `cell` [m] at uv, filtered by the footprint.
float noise(std::uint64_t key, const Eigen::Vector2d& uv, double cell, double footprint) {
  const float w = detailWeight(cell, footprint);
  return w == 0.0f ? 0.5f : fadeToMean(valueNoise(key, uv.x() / cell, uv.y() / cell), w);
}

// Fractal sum of `octaves` value-noise layers (cell sizes cell_u, cell_v halving per octave), in [0, 1), each octave
// filtered by the footprint.
float fbm(std::uint64_t key, const Eigen::Vector2d& uv, double cell_u, double cell_v, int octaves, double footprint) {
  float sum = 0.0f, norm = 0.0f, amp = 1.0f;
  double fu = 1.0 / cell_u, fv = 1.0 / cell_v;
  for (int o = 0; o < octaves; ++o) {
    const float w = detailWeight(1.0 / fu, 1.0 / fv, footprint);
    const std::uint64_t layer = key + static_cast<std::uint64_t>(o) * 0x632BE59BD9B4E019ULL;
    sum += amp * (w == 0.0f ? 0.5f : fadeToMean(valueNoise(layer, uv.x() * fu, uv.y() * fv), w));
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

// Share of [x - f/2, x + f/2] inside the pulses [k period, k period + width): the box-filtered pulse train. f = 0:
// whether x itself is inside one.
double pulseCoverage(double x, double period, double width, double footprint) {
  std::int64_t k = 0;
  if (!(footprint > 0)) return wrap(x, period, k) < width ? 1.0 : 0.0;
  const auto covered = [&](double y) {  // pulse length in [0, y), y >= 0 or not
    const double n = std::floor(y / period);
    return n * width + std::min(y - n * period, width);
  };
  return (covered(x + footprint / 2) - covered(x - footprint / 2)) / footprint;
}

// Mix of a line colour over a share c of the footprint and the colour between the lines.
inline Vector3f cover(double c, const Vector3f& line, const Vector3f& between) {
  if (c >= 1.0) return line;
  if (c <= 0.0) return between;
  return static_cast<float>(c) * line + static_cast<float>(1.0 - c) * between;
}

// The same with colours that cost a noise lookup: only those with a share are computed (at a zero footprint every
// share is 0 or 1, so one).
template <typename Line, typename Between>
Vector3f coverLazily(double c, const Line& line, const Between& between) {
  if (c >= 1.0) return line();
  if (c <= 0.0) return between();
  return cover(c, line(), between());
}

Vector3f brick(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s, double f) {
  const double h = 0.075 * s, w = 0.225 * s, mortar = 0.015 * s;
  std::int64_t row = 0, col = 0;
  const double fv = wrap(uv.y(), h, row);
  const double u = uv.x() + ((row & 1) != 0 ? 0.5 * w : 0.0);
  const double fu = wrap(u, w, col);
  const float grain = noise(key + 1, uv, 0.03 * s, f);
  const Vector3f mortar_colour = Vector3f(0.75f, 0.73f, 0.70f) * (0.85f + 0.3f * grain);
  // A brick's tint fades to the tints' mean (0.95) as the footprint spans bricks.
  const float tint_weight = detailWeight(w, h, f);
  const float tint = 0.6f + 0.7f * fadeToMean(cellValue(key, col, row), tint_weight);
  const Vector3f brick_colour = m.albedo * tint * (0.85f + 0.3f * grain);
  if (!(f > 0)) return fu < mortar || fv < mortar ? mortar_colour : brick_colour;
  const double cv = pulseCoverage(uv.y(), h, mortar, f), cu = pulseCoverage(u, w, mortar, f);
  return cover(1.0 - (1.0 - cu) * (1.0 - cv), mortar_colour, brick_colour);
}

Vector3f fence(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s, double f) {
  const auto post = [&] { return Vector3f(m.albedo * (0.7f + 0.6f * fbm(key, uv, 0.04 * s, 0.4 * s, 2, f))); };
  const auto rail = [&] { return Vector3f(m.albedo * (0.7f + 0.6f * fbm(key + 7, uv, 0.4 * s, 0.04 * s, 2, f))); };
  const auto gap = [&] { return Vector3f(m.albedo * (0.12f + 0.15f * fbm(key + 13, uv, 0.2 * s, 0.2 * s, 2, f))); };
  // Posts (vertical grain) in front of rails (horizontal grain) in front of the dark gap behind the fence.
  const double c_post = pulseCoverage(uv.x(), 1.2 * s, 0.12 * s, f);
  const double c_rail = pulseCoverage(uv.y(), 0.4 * s, 0.08 * s, f);
  return coverLazily(c_post, post, [&] { return coverLazily(c_rail, rail, gap); });
}

// A round bar or rail of width `width` at `x` within it: its highlight across the width, or, once the footprint
// covers the bar, the highlight's mean across it (0.4 + 0.7 * 2 / pi).
float barHighlight(double x, double width, double f) {
  const float mean = 0.4f + 0.7f * static_cast<float>(2.0 / std::numbers::pi);
  const float w = detailWeight(width, f);
  if (w == 0.0f) return mean;
  const float c = 0.4f + 0.7f * static_cast<float>(std::sin(std::numbers::pi * x / width));
  return w == 1.0f ? c : w * c + (1.0f - w) * mean;
}

Vector3f pen(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s, double f) {
  std::int64_t bar = 0, rail = 0;
  const double bar_w = 0.04 * s, rail_w = 0.05 * s;
  const double fu = wrap(uv.x(), 0.15 * s, bar), fv = wrap(uv.y(), 0.5 * s, rail);
  const float dirt = fbm(key, uv, 0.1 * s, 0.1 * s, 2, f);
  const Vector3f inside = m.albedo * (0.1f + 0.15f * dirt);  // the darker pen interior seen between bars
  if (!(f > 0)) {
    if (fu < bar_w) return m.albedo * barHighlight(fu, bar_w, f) * (0.8f + 0.3f * dirt);
    if (fv < rail_w) return m.albedo * barHighlight(fv, rail_w, f) * (0.8f + 0.3f * dirt);
    return inside;
  }
  const Vector3f bars = m.albedo * barHighlight(std::min(fu, bar_w / 2), bar_w, f) * (0.8f + 0.3f * dirt);
  const Vector3f rails = m.albedo * barHighlight(std::min(fv, rail_w / 2), rail_w, f) * (0.8f + 0.3f * dirt);
  return cover(pulseCoverage(uv.x(), 0.15 * s, bar_w, f), bars,
               cover(pulseCoverage(uv.y(), 0.5 * s, rail_w, f), rails, inside));
}

Vector3f carPaint(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s, double f) {
  const float dirt = fbm(key, uv, 0.08 * s, 0.08 * s, 3, f);
  const float shade = 0.75f + 0.5f * dirt * dirt;
  const double cu = pulseCoverage(uv.x(), 0.6 * s, 0.015 * s, f), cv = pulseCoverage(uv.y(), 0.4 * s, 0.015 * s, f);
  const double seam = 1.0 - (1.0 - cu) * (1.0 - cv);  // the panel seams' share
  if (seam >= 1.0) return m.albedo * (0.3f * shade);
  if (seam <= 0.0) return m.albedo * shade;
  return m.albedo * (shade * static_cast<float>(1.0 - 0.7 * seam));
}

Vector3f metal(const Material& m, std::uint64_t key, const Eigen::Vector2d& uv, double s, double f) {
  std::int64_t i = 0, j = 0;
  const double fu = wrap(uv.x(), 1.0 * s, i), fv = wrap(uv.y(), 0.5 * s, j);
  const double ru = fu - 0.06 * s, rv = fv - 0.06 * s;
  // A rivet near each panel corner (0.04 m across at scale 1): dropped once the footprint is a quarter of it (its
  // share of a footprint's box is then small; a point test would put all of it into every box it touches).
  const bool rivet = ru * ru + rv * rv < 0.0004 * s * s && !(f > 0.01 * s);
  const auto panel = [&] {  // brushed streaks along u, or the rivet
    return Vector3f(rivet ? m.albedo * 1.3f : m.albedo * (0.55f + 0.8f * fbm(key, uv, 0.6 * s, 0.04 * s, 2, f)));
  };
  const double cu = pulseCoverage(uv.x(), 1.0 * s, 0.02 * s, f), cv = pulseCoverage(uv.y(), 0.5 * s, 0.02 * s, f);
  return coverLazily(1.0 - (1.0 - cu) * (1.0 - cv), [&] { return Vector3f(m.albedo * 0.25f); }, panel);  // seams
}

Vector3f clamp01(const Vector3f& c) { return c.cwiseMax(0.0f).cwiseMin(1.0f); }

}  // namespace

Eigen::Vector3f shade(const Material& m, const Eigen::Vector2d& uv, double footprint) {
  if (m.texture == Texture::kWhite) return m.albedo;
  const double s = m.scale, f = footprint;
  const std::uint64_t key = hashKeys(m.seed, Stream::kWorld, static_cast<std::uint64_t>(m.texture));
  switch (m.texture) {
    case Texture::kWhite: return m.albedo;
    case Texture::kNoise: return clamp01(m.albedo * (0.25f + 1.5f * fbm(key, uv, 0.15 * s, 0.15 * s, 3, f)));
    case Texture::kBrick: return clamp01(brick(m, key, uv, s, f));
    case Texture::kStraw: {  // streaks 0.3 m long and 0.03 m wide, tinted yellow
      const float n = fbm(key, uv, 0.3 * s, 0.03 * s, 2, f);
      return clamp01(m.albedo.cwiseProduct(Vector3f(1.0f, 0.88f, 0.5f)) * (0.35f + 1.2f * n));
    }
    case Texture::kFence: return clamp01(fence(m, key, uv, s, f));
    case Texture::kPen: return clamp01(pen(m, key, uv, s, f));
    case Texture::kConcrete: {
      const float n = fbm(key, uv, 0.12 * s, 0.12 * s, 3, f);
      const float speck = noise(key + 99, uv, 0.03 * s, f);
      return clamp01(m.albedo * (0.55f + 0.6f * n + 0.25f * speck));
    }
    case Texture::kAsphalt: {
      const float n = fbm(key, uv, 0.08 * s, 0.08 * s, 2, f);
      // Light grains where the noise exceeds 0.75 (14.1 % of the surface): their mean once filtered away.
      const float w = detailWeight(0.03 * s, f);
      const float grain = w == 0.0f ? 0.0f : valueNoise(key + 99, uv.x() / (0.03 * s), uv.y() / (0.03 * s));
      const float grains = grain > 0.75f ? 0.6f : 0.0f;
      return clamp01(m.albedo * (0.45f + 0.6f * n + (w == 1.0f ? grains : w * grains + (1.0f - w) * 0.6f * 0.141f)));
    }
    case Texture::kGrass: {
      const float blades = fbm(key, uv, 0.05 * s, 0.05 * s, 2, f);
      const float patch = noise(key + 99, uv, 0.6 * s, f);
      return clamp01(m.albedo.cwiseProduct(Vector3f(1.0f + 0.3f * patch, 1.0f, 1.0f)) * (0.35f + 1.0f * blades) *
                     (0.75f + 0.5f * patch));
    }
    case Texture::kFoliage: {
      const float n = fbm(key, uv, 0.1 * s, 0.1 * s, 3, f);
      const float leaves = n < 0.42f ? 0.2f + 0.3f * n : 0.6f + 1.0f * (n - 0.42f);  // leaves and gaps
      // Leaves and gaps are a step of the noise: once filtered away their mean is 0.616 (the step over the noise's
      // distribution), not the step at the noise's mean (0.68).
      const float w = detailWeight(0.1 * s, f);  // the coarsest octave's
      return clamp01(m.albedo * (w == 1.0f ? leaves : w * leaves + (1.0f - w) * 0.616f));
    }
    case Texture::kBark: return clamp01(m.albedo * (0.3f + 1.1f * fbm(key, uv, 0.04 * s, 0.4 * s, 3, f)));
    case Texture::kCarPaint: return clamp01(carPaint(m, key, uv, s, f));
    case Texture::kMetal: return clamp01(metal(m, key, uv, s, f));
  }
  return m.albedo;
}

}  // namespace drover::sim
