#pragma once
// Procedural textures: the colour of a material at surface coordinates uv [m]. Pure functions (no state), so
// rendering is deterministic and thread-safe.
#include <Eigen/Core>

#include "sim/world.hpp"

namespace drover::sim {

// Linear RGB in [0, 1] of `material` at `uv` [m]. kWhite returns the albedo unchanged everywhere. Patterns assume u
// horizontal and v up on vertical surfaces (World's uv convention), scale with material.scale (features ~0.03-1.2 m
// at scale 1) and vary with material.seed. The albedo is the base colour of every pattern (kStraw tints it yellow;
// kBrick mortar, fence gaps and pen interiors are fixed light grey / dark).
// footprint [m]: the width of surface the sample stands for (a camera ray's share of a pixel there); the pattern is
// then its average over a footprint-wide square instead of its value at uv. 0: the point value.
Eigen::Vector3f shade(const Material& material, const Eigen::Vector2d& uv, double footprint = 0);

}  // namespace drover::sim
