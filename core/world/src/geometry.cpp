#include <dicestack/core/geometry.hpp>

#include <algorithm>
#include <cmath>

namespace dicestack {

CupGeometry cup_geometry(const CupConfig& cup) {
  const double w = cup.base_width, h = cup.wall_height, f = cup.flare;
  // Anchor frame: base from (0, 0) to (w, 0); walls rise to (-f, h) and (w + f, h).
  const std::array<RoundedSegment, 3> anchor{{{{-f, h}, {0.0, 0.0}, cup.radius},
                                              {{0.0, 0.0}, {w, 0.0}, cup.radius},
                                              {{w, 0.0}, {w + f, h}, cup.radius}}};
  CupGeometry g;
  g.mass = 3.0 * cup.segment_mass;
  Vec2 com{};
  for (const auto& s : anchor) {
    com.x += (s.a.x + s.b.x) / 6.0;  // equal masses: mean of the three midpoints
    com.y += (s.a.y + s.b.y) / 6.0;
  }
  g.com_from_anchor = com;
  g.inertia = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& s = anchor[i];
    g.segments[i] = {{s.a.x - com.x, s.a.y - com.y}, {s.b.x - com.x, s.b.y - com.y}, s.radius};
    // Chipmunk's segment moment: a box of (length + 2r) x 2r, plus the parallel-axis term.
    const double len = std::hypot(s.b.x - s.a.x, s.b.y - s.a.y) + 2.0 * s.radius;
    const double mx = 0.5 * (s.a.x + s.b.x) - com.x, my = 0.5 * (s.a.y + s.b.y) - com.y;
    g.inertia += cup.segment_mass * ((len * len + 4.0 * s.radius * s.radius) / 12.0 + mx * mx + my * my);
  }
  return g;
}

std::array<Vec2, 8> die_vertices(const DiceConfig& dice) {
  const double h = dice.half_size, c = dice.half_size - dice.corner_cut;
  return {{{h, -c}, {h, c}, {c, h}, {-c, h}, {-h, c}, {-h, -c}, {-c, -h}, {c, -h}}};
}

double die_inertia(const DiceConfig& dice) {
  // Second moment of a uniform polygon about the origin (its centroid, by symmetry).
  const auto v = die_vertices(dice);
  double area2 = 0.0, moment = 0.0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const Vec2 p = v[i], q = v[(i + 1) % v.size()];
    const double cross = p.x * q.y - q.x * p.y;
    area2 += cross;
    moment += cross * (p.x * p.x + p.x * q.x + q.x * q.x + p.y * p.y + p.y * q.y + q.y * q.y);
  }
  return dice.mass * moment / (6.0 * area2);
}

Vec2 to_world(Vec2 origin, double angle, Vec2 p) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {origin.x + c * p.x - s * p.y, origin.y + s * p.x + c * p.y};
}

double cup_reach(const CupGeometry& cup, double angle, double side) {
  double m = -1e300;
  for (const auto& seg : cup.segments)
    for (const Vec2 q : {seg.a, seg.b}) m = std::max(m, side * to_world({0.0, 0.0}, angle, q).x + seg.radius);
  return m;
}

Vec2 to_local(Vec2 origin, double angle, Vec2 p) {
  const double c = std::cos(angle), s = std::sin(angle);
  const double dx = p.x - origin.x, dy = p.y - origin.y;
  return {c * dx + s * dy, -s * dx + c * dy};
}

}  // namespace dicestack
