#pragma once
// The paper's state distance and goal cost (eq. 6), used by the optimisers and as the
// environment's reward.
#include <span>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// Scaled L2 distance between two states: sqrt(sum_j ((a_j - b_j) / sigma_j)^2) over the dice
/// and the cup's velocity (indices 3-23), as the original implementation compared states; the
/// cup's pose is free. Die angles compare modulo 90 degrees (a turned die is the same die).
double state_distance(const State& a, const State& b, const CostConfig& cost);

/// Squared scaled L2 distance over all 24 dimensions, die angles modulo 90 degrees: how far a
/// state is from the demonstration state it should follow (eq. 11; the cup's pose counts).
double tracking_distance_sq(const State& a, const State& b, const CostConfig& cost);

/// The same over the cup's pose alone (x, y, angle): how far the cup is from a recorded cup path,
/// whatever the dice do (DaD's corrections towards the recording's cup path).
double cup_distance_sq(const State& a, const State& b, const CostConfig& cost);

/// Eq. 6 for one trajectory s_1..s_T: sum_j gamma^(T - j) d(s_j, goal).
double discounted_cost(std::span<const State> trajectory, const State& goal, const CostConfig& cost);

}  // namespace dicestack
