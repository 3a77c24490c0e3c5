#pragma once
// Counter-based random numbers for the simulator. Every noise value is a pure function of (seed, stream, index...),
// so output is byte-identical for a seed whatever the thread count or the order in which work is done.
#include <cmath>
#include <cstdint>
#include <numbers>

namespace drover::sim {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mixer.
inline std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

// Hash of several keys, e.g. hashKeys(seed, kStreamLidar, scan, column, ring).
template <typename... Keys>
std::uint64_t hashKeys(std::uint64_t first, Keys... rest) {
  std::uint64_t h = mix64(first);
  ((h = mix64(h ^ static_cast<std::uint64_t>(rest))), ...);
  return h;
}

// Uniform in [0, 1) from a hash (53 random bits).
inline double uniform01(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

// Standard normal from a hash, by Box-Muller on two derived uniforms (own maths: std::normal_distribution's
// output differs between standard libraries).
inline double standardNormal(std::uint64_t h) {
  const double u1 = 1.0 - uniform01(mix64(h));  // (0, 1]
  const double u2 = uniform01(mix64(h ^ 0xD1B54A32D192ED03ULL));
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

// Streams: one constant per noise source so sources never share numbers.
enum class Stream : std::uint64_t { kImu = 1, kLidar = 2, kCamera = 3, kWorld = 4, kScenario = 5 };

}  // namespace drover::sim
