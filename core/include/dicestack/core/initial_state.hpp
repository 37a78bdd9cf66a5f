#pragma once
// Where episodes start and where the optimisers' cost wants them to end.
#include <cstdint>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// The paper's start: the cup hanging mouth-down over three dice lying in a row (DESIGN table).
State paper_start_state(const WorldConfig& config);

/// A start drawn from config.randomization with `seed`: the scene shifted in x, each die
/// jittered and turned by a multiple of 90 degrees, the cup lifted and tilted. Draws again
/// (deterministically) while shapes overlap. Throws ConfigError if no valid start is found.
State random_start_state(const WorldConfig& config, std::uint64_t seed);

/// The paper's goal: the three dice at rest in one column at cost.goal_x on the table, die 0
/// at the bottom, unrotated; the cup at its start pose and at rest.
State goal_state(const WorldConfig& config);

}  // namespace dicestack
