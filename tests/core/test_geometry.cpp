#include <gtest/gtest.h>

#include <dicestack/core/geometry.hpp>

namespace dicestack {
namespace {

TEST(Geometry, CupCentreOfMassAndInertiaMatchTheOriginal) {
  const CupGeometry g = cup_geometry(CupConfig{});
  EXPECT_NEAR(g.com_from_anchor.x, 0.5, 1e-12);
  EXPECT_NEAR(g.com_from_anchor.y, 2.2 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(g.mass, 15.0);
  // Pymunk's moment for the original cup: about 125,931.8 kg px^2.
  EXPECT_NEAR(g.inertia, 12.59318, 1e-4);
}

TEST(Geometry, DieInertiaMatchesPymunk) {
  // pymunk.moment_for_poly(1, die, (0, 0)) is about 253.49 kg px^2.
  EXPECT_NEAR(die_inertia(DiceConfig{}), 0.025349, 1e-5);
  const auto v = die_vertices(DiceConfig{});
  EXPECT_DOUBLE_EQ(v[0].x, 0.20);
  EXPECT_DOUBLE_EQ(v[0].y, -0.15);
}

TEST(Geometry, FramesRoundTrip) {
  const Vec2 origin{1.0, 2.0};
  const Vec2 p{0.3, -0.7};
  const Vec2 back = to_local(origin, 0.9, to_world(origin, 0.9, p));
  EXPECT_NEAR(back.x, p.x, 1e-12);
  EXPECT_NEAR(back.y, p.y, 1e-12);
}

}  // namespace
}  // namespace dicestack
