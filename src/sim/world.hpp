#pragma once
// A simulated world of simple primitives (infinite ground plane, oriented boxes, vertical cylinders, oriented
// rectangles for ramps, walls and fences), each with a material, and ray casting against it through a bounding
// volume hierarchy. World frame: z up [m]. All queries are const and thread-safe after build().
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace drover::sim {

// Procedural surface patterns (see texture.hpp). kWhite: a textureless white wall (no gradients at all).
enum class Texture : std::uint8_t {
  kNoise, kBrick, kStraw, kFence, kPen, kWhite, kConcrete, kAsphalt, kGrass, kFoliage, kBark, kCarPaint, kMetal
};

struct Material {
  Texture texture = Texture::kNoise;
  Eigen::Vector3f albedo = Eigen::Vector3f::Constant(0.6f);  // base colour, linear RGB in [0, 1]
  float reflectivity = 0.5f;   // lidar return strength in [0, 1]; low (dark, e.g. 0.05) surfaces drop out far away
  float scale = 1.0f;          // texture feature size [m] (brick height, noise cell, straw blade length)
  std::uint32_t seed = 0;      // varies the pattern between surfaces with the same texture
};

struct Ray {
  Eigen::Vector3d origin;     // [m], world
  Eigen::Vector3d direction;  // unit, world
};

struct Hit {
  double distance = 0;                     // along the ray [m]
  Eigen::Vector3d point;                   // world [m]
  Eigen::Vector3d normal;                  // unit, world, facing the ray origin
  Eigen::Vector2d uv;                      // surface coordinates [m] for texturing (metres along the surface)
  std::uint32_t primitive = 0;             // index of the primitive hit
  const Material* material = nullptr;      // owned by the World
};

// An oriented box: centre pose and half extents along its own axes.
struct Box {
  Eigen::Isometry3d T_world_box = Eigen::Isometry3d::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Constant(0.5);  // [m]
};
// A vertical (world z) cylinder with caps.
struct Cylinder {
  Eigen::Vector3d base_center = Eigen::Vector3d::Zero();  // [m], centre of the bottom cap
  double radius = 0.5;                                    // [m]
  double height = 1.0;                                    // [m]
};
// A one- or two-sided rectangle: centre pose, the rectangle spans local x in [-hx, hx], y in [-hy, hy], normal +z.
// Ramps, walls, fences and ceilings are rectangles.
struct Rectangle {
  Eigen::Isometry3d T_world_rect = Eigen::Isometry3d::Identity();
  Eigen::Vector2d half_size = Eigen::Vector2d::Constant(0.5);  // [m]
};

// A region that is indoors (under a roof): the camera's lighting and the scenario labels use it.
struct IndoorRegion {
  Eigen::Vector3d min_corner, max_corner;  // axis-aligned [m]
};

// Copies of a World share its (immutable after build()) contents: copying is cheap.
class World {
 public:
  // Hit::primitive of a ground-plane hit (the ground is not one of the indexed primitives).
  static constexpr std::uint32_t kGroundPrimitive = 0xFFFFFFFFu;

  // The ground plane z = ground_height everywhere (ramps are rectangles placed on top of it).
  void setGround(double ground_height, const Material& material);
  std::uint32_t addBox(const Box& box, const Material& material);
  std::uint32_t addCylinder(const Cylinder& cylinder, const Material& material);
  std::uint32_t addRectangle(const Rectangle& rect, const Material& material);
  void addIndoorRegion(const IndoorRegion& region);

  // Builds the acceleration structure; call once after adding everything (intersect() before build() throws).
  void build();

  // Nearest hit with distance in (t_min, t_max), or nothing (sky / out of range).
  // Surface coordinates uv [m]: ground (x, y) world; box side faces (horizontal in-face local axis, local z), box
  // top/bottom faces (local x, local y); cylinder side (arc length r * atan2, height above base), caps (x, y) from
  // the axis; rectangle (local x, local y). So on vertical faces v runs up when the primitive's local z is world up.
  std::optional<Hit> intersect(const Ray& ray, double t_min = 1e-4, double t_max = 1e4) const;
  // The same answer by testing every primitive (no BVH): the reference for tests and benchmarks.
  std::optional<Hit> intersectBruteForce(const Ray& ray, double t_min = 1e-4, double t_max = 1e4) const;
  bool isIndoor(const Eigen::Vector3d& p_world) const;
  std::size_t primitiveCount() const;  // boxes + cylinders + rectangles (not the ground)

 private:
  struct Impl;  // implementation's choice (the helper that implements this owns the private part)
  Impl& mutableImpl();  // creates the Impl on first use; throws std::logic_error after build()
  std::shared_ptr<Impl> impl_;
};

}  // namespace drover::sim
