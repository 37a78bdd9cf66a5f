#pragma once
// The shapes of the cup and the dice, derived from a WorldConfig, in SI units. Shared by the
// physics, the outcome judge and the renderer so that all three agree on one geometry.
#include <array>

#include <dicestack/core/vec2.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// A rounded segment (a capsule): the points within `radius` of the line from a to b.
struct RoundedSegment {
  Vec2 a;
  Vec2 b;
  double radius = 0.0;
};

/// The cup in its own frame: origin at the centre of mass, mouth up at angle 0.
struct CupGeometry {
  std::array<RoundedSegment, 3> segments;  ///< left wall, base, right wall
  Vec2 com_from_anchor;  ///< centre of mass relative to the base's left end, m
  double mass = 0.0;     ///< kg
  double inertia = 0.0;  ///< about the centre of mass, kg m^2 (Chipmunk's segment formula)
};

/// Builds the cup of `cup` (three segments of equal mass).
CupGeometry cup_geometry(const CupConfig& cup);

/// The die octagon around its centre, counter-clockwise, m.
std::array<Vec2, 8> die_vertices(const DiceConfig& dice);

/// Moment of inertia of a uniform die about its centre, kg m^2.
double die_inertia(const DiceConfig& dice);

/// How far the cup at `angle` reaches from its centre of mass towards `side` (+1 right, -1
/// left), rims included, m: a side wall touches it when its centre is this close.
double cup_reach(const CupGeometry& cup, double angle, double side);

/// Rotates p by `angle` and adds `origin`.
Vec2 to_world(Vec2 origin, double angle, Vec2 p);

/// Expresses world point p in a frame at `origin` rotated by `angle`.
Vec2 to_local(Vec2 origin, double angle, Vec2 p);

/// The table surface height (top of the floor), m.
inline double table_height(const WallsConfig& walls) { return walls.floor_y + walls.radius; }

}  // namespace dicestack
