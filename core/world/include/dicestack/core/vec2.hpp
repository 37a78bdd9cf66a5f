#pragma once
// A point or vector in the plane of the world, in metres (or m/s, m/s^2 where a field says so).

namespace dicestack {

struct Vec2 {
  double x = 0.0;
  double y = 0.0;
  bool operator==(const Vec2&) const = default;
};

}  // namespace dicestack
