#pragma once
// The baseline of `dicestack bench sim`: the world's Box2D scene stepped with nothing around it.
// A measurement aid, not part of the World API (world.hpp); it lives in core/world because it
// builds exactly the bodies a World builds.
#include <cstdint>

#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// Runs `episodes` episodes of `steps` control steps with random actions on a bare Box2D loop
/// (the same bodies, no framework around it) and returns the seconds taken. The benchmark's
/// baseline for the framework's own overhead (issue: bench sim).
double bare_box2d_seconds(const WorldConfig& config, int episodes, int steps, std::uint64_t seed);

}  // namespace dicestack
