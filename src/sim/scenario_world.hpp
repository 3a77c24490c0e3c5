#pragma once
// Internal to the scenarios: building worlds around a course. Structures (barns, ramps, corridors, walls) are
// placed by design; decorations (trees, bales, fences, pens, parked cars, facades) are queued and kept only where
// their footprint stays clear of every part of the path and outside keep-out zones (e.g. the corridor's axis).
// Lighting: a scene-wide illumination from indoor regions and timed lighting events.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "sim/camera_model.hpp"
#include "sim/scenario_course.hpp"
#include "sim/world.hpp"

namespace drover::sim::detail {

Material makeMaterial(Texture texture, const Eigen::Vector3f& albedo, float reflectivity, float scale,
                      std::uint32_t seed);
// A vertical rectangle from a to b (plane points) between heights z0 and z1; local x along a -> b, local y up.
Rectangle verticalRect(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double z0, double z1);
// A box with its base at `base` (centre of the bottom face), half extents, turned by yaw about z.
Box yawBox(const Eigen::Vector3d& base, const Eigen::Vector3d& half, double yaw);
// Footprint of a box or a vertical rectangle in the plane.
Footprint footprintOf(const Box& box);
Footprint footprintOf(const Rectangle& vertical_rect);

// Timed lighting: within [start, end] the scene light follows a ramp down to dark (geometric: the light falls by the
// same factor per second, as at dusk), a dark stretch, a ramp back up and then flicker (mains flicker aliased to a
// few Hz by the camera rate). `dark` is a night light level: 5e-4 of daylight, e.g. ~5-50 lux under a lamp against
// ~10^4-10^5 lux of daylight; indoors (x 0.5) it is below what the camera's auto exposure can make up for
// (camera_exposure.hpp: exposure and gain give ~500x), so the images get dark and noisy, as at night.
struct LightingEvent {
  Time start = 0, end = 0;  // [ns]
};
struct LightingPlan {
  float outdoor = 1.0f, indoor = 0.5f, dark = 5e-4f;
  float flicker_depth = 0.3f;
  double flicker_hz = 4.0;  // [Hz], e.g. 100 Hz mains seen by a 15.2 Hz camera
  std::vector<IndoorRegion> indoor_regions;
  std::vector<LightingEvent> events;
  float temporal(Time t) const;  // factor of the events at t (1 outside them)
  float at(Time t, const Eigen::Vector3d& p_world) const;
};
Illumination makeIllumination(const LightingPlan& plan);

class WorldBuilder {
 public:
  void ground(double height, const Material& m) { world_.setGround(height, m); }
  void structure(const Box& b, const Material& m) { world_.addBox(b, m); }
  void structure(const Rectangle& r, const Material& m) { world_.addRectangle(r, m); }
  void structure(const Cylinder& c, const Material& m) { world_.addCylinder(c, m); }
  void decor(const Box& b, const Material& m, double clearance);
  void decor(const Rectangle& vertical_rect, const Material& m, double clearance);
  void decor(const Cylinder& c, const Material& m, double clearance);
  // A tree: bark trunk and a foliage box; one decoration (both or neither).
  void tree(const Eigen::Vector3d& base, double height, double crown, std::uint32_t seed, double clearance);
  void keepOut(const Footprint& zone) { keep_out_.push_back(zone); }
  void indoor(const IndoorRegion& region);
  const std::vector<IndoorRegion>& indoorRegions() const { return indoor_; }
  // Adds the decorations that keep clear of the path and the keep-out zones, builds and returns the world.
  World finish(const PathIndex& path);

 private:
  struct Item {
    std::vector<Box> boxes;
    std::vector<Rectangle> rects;
    std::vector<Cylinder> cylinders;
    std::vector<Material> box_m, rect_m, cyl_m;
    std::vector<Footprint> footprints;
    double clearance = 0;
  };
  World world_;
  std::vector<Item> items_;
  std::vector<Footprint> keep_out_;
  std::vector<IndoorRegion> indoor_;
};

}  // namespace drover::sim::detail
