// World ray casting: closed-form hits on each primitive kind (distance, normal facing the origin, uv), misses and
// grazing rays, and the BVH against a brute-force scan over a random world.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "sim/random.hpp"
#include "sim/world.hpp"

namespace drover::sim {
namespace {

constexpr double kTol = 1e-9;

Ray makeRay(const Eigen::Vector3d& o, const Eigen::Vector3d& d) { return Ray{o, d.normalized()}; }

Material seeded(std::uint32_t seed) {
  Material m;
  m.seed = seed;
  return m;
}

void expectVec(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol = kTol) {
  EXPECT_LT((actual - expected).norm(), tol) << "actual " << actual.transpose() << " expected " << expected.transpose();
}
void expectUv(const Eigen::Vector2d& actual, const Eigen::Vector2d& expected, double tol = kTol) {
  EXPECT_LT((actual - expected).norm(), tol) << "actual " << actual.transpose() << " expected " << expected.transpose();
}

World boxWorld(const Box& box) {
  World w;
  w.addBox(box, seeded(7));
  w.build();
  return w;
}

TEST(World, BoxHitFromOutsideGivesEntryFaceDistanceNormalAndUv) {
  Box box;
  box.T_world_box.translation() = Eigen::Vector3d(5, 0, 0);
  box.half_extents = Eigen::Vector3d(1, 2, 3);
  const World w = boxWorld(box);
  const auto hit = w.intersect(makeRay({0, 0.5, 1}, {1, 0, 0}));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 4.0, kTol);
  expectVec(hit->point, {4, 0.5, 1});
  expectVec(hit->normal, {-1, 0, 0});
  expectUv(hit->uv, {0.5, 1.0});  // side face: (in-face horizontal axis y, z)
  EXPECT_EQ(hit->primitive, 0u);
  ASSERT_NE(hit->material, nullptr);
  EXPECT_EQ(hit->material->seed, 7u);
}

TEST(World, BoxHitFromInsideGivesExitFaceWithNormalTowardsOrigin) {
  Box box;
  box.half_extents = Eigen::Vector3d(1, 2, 3);
  const World w = boxWorld(box);
  const auto hit = w.intersect(makeRay({0.25, 0, -1}, {0, 1, 0}));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 2.0, kTol);
  expectVec(hit->normal, {0, -1, 0});
  expectUv(hit->uv, {0.25, -1.0});
  const auto top = w.intersect(makeRay({0.5, -0.5, 0}, {0, 0, 1}));
  ASSERT_TRUE(top);
  EXPECT_NEAR(top->distance, 3.0, kTol);
  expectVec(top->normal, {0, 0, -1});
  expectUv(top->uv, {0.5, -0.5});  // top/bottom faces: (x, y)
}

TEST(World, RotatedBoxUsesItsOwnAxesForUv) {
  // Rotated 90 deg about z: local x -> world y, local y -> world -x, so it spans x in [-2, 2], y in [-1, 1].
  Box box;
  box.T_world_box.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  box.half_extents = Eigen::Vector3d(1, 2, 0.5);
  const World w = boxWorld(box);
  const auto hit = w.intersect(makeRay({-5, 0.3, 0.2}, {1, 0, 0}));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 3.0, kTol);
  expectVec(hit->normal, {-1, 0, 0});
  expectUv(hit->uv, {0.3, 0.2});  // local +y face: (local x, local z)
  // Oblique ray from outside onto the world +x face (x = 2).
  const Eigen::Vector3d o(5, 0, 0), target(2, 0.5, 0.1);
  const auto oblique = w.intersect(makeRay(o, target - o));
  ASSERT_TRUE(oblique);
  EXPECT_NEAR(oblique->distance, (target - o).norm(), kTol);
  expectVec(oblique->point, target);
}

TEST(World, BoxMissesParallelRayOutsideSlabAndRayPassingBeside) {
  Box box;
  box.T_world_box.translation() = Eigen::Vector3d(5, 0, 0);
  box.half_extents = Eigen::Vector3d(1, 2, 3);
  const World w = boxWorld(box);
  EXPECT_FALSE(w.intersect(makeRay({0, 2.0001, 0}, {1, 0, 0})));   // parallel, just outside the y slab
  EXPECT_TRUE(w.intersect(makeRay({0, 1.9999, 0}, {1, 0, 0})));    // parallel, just inside it
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 0}, {1, 0.55, 0})));     // passes beside: y = 2.2 > 2 already at x = 4
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 0}, {-1, 0, 0})));       // points away
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 0}, {1, 0, 0}), 1e-4, 3.9));  // beyond t_max
}

World cylinderWorld() {
  World w;
  Cylinder c;
  c.base_center = Eigen::Vector3d(0, 0, 0);
  c.radius = 1.0;
  c.height = 2.0;
  w.addCylinder(c, seeded(3));
  w.build();
  return w;
}

TEST(World, CylinderSideHitFromOutsideHasRadialNormalAndArcLengthUv) {
  const World w = cylinderWorld();
  const auto hit = w.intersect(makeRay({-5, 0.6, 1.5}, {1, 0, 0}));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->distance, 5.0 - 0.8, kTol);  // x = -sqrt(1 - 0.36)
  expectVec(hit->normal, {-0.8, 0.6, 0});
  expectUv(hit->uv, {std::atan2(0.6, -0.8), 1.5});
}

TEST(World, CylinderHitFromInsideFacesOrigin) {
  const World w = cylinderWorld();
  const auto side = w.intersect(makeRay({0, 0, 1}, {1, 0, 0}));
  ASSERT_TRUE(side);
  EXPECT_NEAR(side->distance, 1.0, kTol);
  expectVec(side->normal, {-1, 0, 0});
  expectUv(side->uv, {0.0, 1.0});
  const auto cap = w.intersect(makeRay({0.2, 0.1, 1}, {0, 0, 1}));
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->distance, 1.0, kTol);
  expectVec(cap->normal, {0, 0, -1});
  expectUv(cap->uv, {0.2, 0.1});
}

TEST(World, CylinderCapHitFromAboveAndMissesAboveOrBeside) {
  const World w = cylinderWorld();
  const auto cap = w.intersect(makeRay({0.3, 0.4, 10}, {0, 0, -1}));
  ASSERT_TRUE(cap);
  EXPECT_NEAR(cap->distance, 8.0, kTol);
  expectVec(cap->normal, {0, 0, 1});
  expectUv(cap->uv, {0.3, 0.4});
  EXPECT_FALSE(w.intersect(makeRay({-5, 0, 2.01}, {1, 0, 0})));   // above the top cap
  EXPECT_FALSE(w.intersect(makeRay({-5, 1.01, 1}, {1, 0, 0})));   // grazes past the side
  EXPECT_FALSE(w.intersect(makeRay({0.9, 0.9, 5}, {0, 0, -1})));  // outside the radius (corner of the AABB)
}

World wallWorld() {
  // Rotation about y by 90 deg: local z -> world +x, local x -> world -z, local y -> world y.
  World w;
  Rectangle r;
  r.T_world_rect.linear() = Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  r.T_world_rect.translation() = Eigen::Vector3d(3, 0, 1);
  r.half_size = Eigen::Vector2d(1, 2);
  w.addRectangle(r, seeded(5));
  w.build();
  return w;
}

TEST(World, RectangleIsTwoSidedWithNormalFacingOrigin) {
  const World w = wallWorld();
  const auto front = w.intersect(makeRay({0, 0.5, 0.5}, {1, 0, 0}));
  ASSERT_TRUE(front);
  EXPECT_NEAR(front->distance, 3.0, kTol);
  expectVec(front->normal, {-1, 0, 0});
  expectUv(front->uv, {0.5, 0.5});  // local x = -(z - 1), local y = y
  const auto back = w.intersect(makeRay({6, 0.5, 0.5}, {-1, 0, 0}));
  ASSERT_TRUE(back);
  EXPECT_NEAR(back->distance, 3.0, kTol);
  expectVec(back->normal, {1, 0, 0});
  const Eigen::Vector3d o(0, 0, 0), target(3, -1.5, 1.25);
  const auto oblique = w.intersect(makeRay(o, target - o));
  ASSERT_TRUE(oblique);
  EXPECT_NEAR(oblique->distance, target.norm(), kTol);
  expectUv(oblique->uv, {-0.25, -1.5});
}

TEST(World, RectangleMissesOutsideItsExtentAndInItsPlane) {
  const World w = wallWorld();
  EXPECT_FALSE(w.intersect(makeRay({0, 2.01, 0.5}, {1, 0, 0})));
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 2.01}, {1, 0, 0})));
  EXPECT_FALSE(w.intersect(makeRay({3, -5, 1}, {0, 1, 0})));  // grazing: in the plane, zero thickness
}

TEST(World, GroundPlaneHitsFromAboveAndBelowWithWorldXyUv) {
  World w;
  w.setGround(-0.5, seeded(11));
  w.build();
  const auto down = w.intersect(makeRay({1, 2, 1.5}, {0, 0, -1}));
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->distance, 2.0, kTol);
  expectVec(down->normal, {0, 0, 1});
  expectUv(down->uv, {1, 2});
  EXPECT_EQ(down->primitive, World::kGroundPrimitive);
  EXPECT_EQ(down->material->seed, 11u);
  const auto oblique = w.intersect(makeRay({1, 2, 1.5}, {1, 0, -1}));
  ASSERT_TRUE(oblique);
  EXPECT_NEAR(oblique->distance, 2.0 * std::sqrt(2.0), kTol);
  expectUv(oblique->uv, {3, 2});
  const auto up = w.intersect(makeRay({0, 0, -3}, {0, 0, 1}));
  ASSERT_TRUE(up);
  expectVec(up->normal, {0, 0, -1});
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 1}, {1, 0, 0})));       // parallel
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 1}, {0, 0, 1})));       // away from it
  EXPECT_FALSE(w.intersect(makeRay({0, 0, 1.5}, {0, 0, -1}), 1e-4, 1.9));  // beyond t_max
}

TEST(World, NearestOfOverlappingPrimitivesWins) {
  World w;
  w.setGround(0.0, seeded(0));
  Box far_box, near_box;
  far_box.T_world_box.translation() = Eigen::Vector3d(10, 0, 1);
  near_box.T_world_box.translation() = Eigen::Vector3d(6, 0, 1);
  const auto far_id = w.addBox(far_box, seeded(1));
  const auto near_id = w.addBox(near_box, seeded(2));
  w.build();
  const auto hit = w.intersect(makeRay({0, 0, 1}, {1, 0, 0}));
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->primitive, near_id);
  EXPECT_NEAR(hit->distance, 5.5, kTol);
  const auto behind = w.intersect(makeRay({0, 0, 1}, {1, 0, 0}), 5.6);  // t_min skips the near box's front face
  ASSERT_TRUE(behind);
  EXPECT_EQ(behind->primitive, near_id);
  EXPECT_NEAR(behind->distance, 6.5, kTol);  // its back face, seen from inside the (t_min) interval
  const auto past = w.intersect(makeRay({0, 0, 1}, {1, 0, 0}), 6.6);
  ASSERT_TRUE(past);
  EXPECT_EQ(past->primitive, far_id);
}

World randomWorld(std::uint64_t seed, int count) {
  World w;
  w.setGround(0.0, seeded(0));
  const auto u = [&](int i, int k, double lo, double hi) {
    return lo + (hi - lo) * uniform01(hashKeys(seed, Stream::kWorld, static_cast<std::uint64_t>(i), k));
  };
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d c(u(i, 0, -50, 50), u(i, 1, -50, 50), u(i, 2, 0, 8));
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(u(i, 3, -1, 1), u(i, 4, -1, 1), u(i, 5, -1, 1), u(i, 6, -1, 1)).normalized();
    const Material m = seeded(static_cast<std::uint32_t>(i));
    switch (i % 3) {
      case 0: {
        Box b;
        b.T_world_box.linear() = q.toRotationMatrix();
        b.T_world_box.translation() = c;
        b.half_extents = Eigen::Vector3d(u(i, 7, 0.1, 4), u(i, 8, 0.1, 4), u(i, 9, 0.1, 4));
        w.addBox(b, m);
        break;
      }
      case 1: {
        Cylinder cy;
        cy.base_center = c;
        cy.radius = u(i, 7, 0.1, 2);
        cy.height = u(i, 8, 0.2, 6);
        w.addCylinder(cy, m);
        break;
      }
      default: {
        Rectangle r;
        r.T_world_rect.linear() = q.toRotationMatrix();
        r.T_world_rect.translation() = c;
        r.half_size = Eigen::Vector2d(u(i, 7, 0.2, 6), u(i, 8, 0.2, 6));
        w.addRectangle(r, m);
      }
    }
  }
  w.build();
  return w;
}

TEST(World, BvhAgreesWithBruteForceOnRandomRaysInRandomWorld) {
  const World w = randomWorld(42, 300);
  ASSERT_EQ(w.primitiveCount(), 300u);
  int hits = 0, primitive_hits = 0;
  for (std::uint64_t i = 0; i < 20000; ++i) {
    const auto u = [&](int k) { return uniform01(hashKeys(99, Stream::kWorld, i, k)); };
    const Eigen::Vector3d o(-60 + 120 * u(0), -60 + 120 * u(1), 0.1 + 10 * u(2));
    const Eigen::Vector3d d(u(3) - 0.5, u(4) - 0.5, 0.5 * (u(5) - 0.6));
    const Ray ray = makeRay(o, d);
    const double t_max = i % 4 == 0 ? 20.0 : 1e4;
    const auto bvh = w.intersect(ray, 1e-4, t_max);
    const auto ref = w.intersectBruteForce(ray, 1e-4, t_max);
    ASSERT_EQ(bvh.has_value(), ref.has_value()) << "ray " << i;
    if (!bvh) continue;
    ++hits;
    primitive_hits += bvh->primitive != World::kGroundPrimitive;
    ASSERT_EQ(bvh->primitive, ref->primitive) << "ray " << i;
    ASSERT_EQ(bvh->distance, ref->distance) << "ray " << i;
    ASSERT_EQ(bvh->normal, ref->normal) << "ray " << i;
    ASSERT_EQ(bvh->uv, ref->uv) << "ray " << i;
  }
  EXPECT_GT(hits, 10000);            // the comparison covered many hits ...
  EXPECT_GT(primitive_hits, 2000);   // ... of primitives, not only the ground
}

TEST(World, IsIndoorInsideRegionsOnly) {
  World w;
  w.addIndoorRegion({Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 5, 3)});
  w.addIndoorRegion({Eigen::Vector3d(20, 0, 0), Eigen::Vector3d(30, 5, 3)});
  w.build();
  EXPECT_TRUE(w.isIndoor({5, 2, 1}));
  EXPECT_TRUE(w.isIndoor({25, 4.9, 2.9}));
  EXPECT_TRUE(w.isIndoor({10, 5, 3}));  // boundary counts as inside
  EXPECT_FALSE(w.isIndoor({15, 2, 1}));
  EXPECT_FALSE(w.isIndoor({5, 2, 3.1}));
  EXPECT_FALSE(World().isIndoor({0, 0, 0}));
}

TEST(World, MisuseThrows) {
  World w;
  EXPECT_THROW(w.intersect(makeRay({0, 0, 0}, {1, 0, 0})), std::logic_error);
  Box bad;
  bad.half_extents = Eigen::Vector3d(1, 0, 1);
  EXPECT_THROW(w.addBox(bad, Material{}), std::invalid_argument);
  Cylinder thin;
  thin.radius = -1;
  EXPECT_THROW(w.addCylinder(thin, Material{}), std::invalid_argument);
  Material m;
  m.scale = 0;
  EXPECT_THROW(w.addBox(Box{}, m), std::invalid_argument);
  EXPECT_THROW(w.addIndoorRegion({Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 1)}), std::invalid_argument);
  w.addBox(Box{}, Material{});
  w.build();
  EXPECT_THROW(w.addBox(Box{}, Material{}), std::logic_error);
}

TEST(World, CopiesAnswerLikeTheOriginal) {
  const World original = randomWorld(7, 60);
  const World copy = original;  // NOLINT(performance-unnecessary-copy-initialization): copying is the test
  const Ray ray = makeRay({-60, 0, 2}, {1, 0.01, 0});
  const auto a = original.intersect(ray), b = copy.intersect(ray);
  ASSERT_EQ(a.has_value(), b.has_value());
  if (a) {
    EXPECT_EQ(a->distance, b->distance);
  }
  EXPECT_EQ(copy.primitiveCount(), 60u);
}

}  // namespace
}  // namespace drover::sim
