#pragma once
// Recovering what demonstration format v1 did not store (the final state, the rewards and how an
// episode ended) by replaying an episode in dicestack's deterministic world, and judging
// recorded states that came without our outcome.
#include <string>
#include <vector>

#include <dicestack/core/judge.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/episode.hpp>

namespace dicestack {

/// Largest difference (any of the 24 state numbers, SI) between a replayed and a recorded state
/// that still counts as reproducing the recording. Replays of our own rollouts agree exactly;
/// the tolerance only forgives the last bits of a state read back and set again.
inline constexpr double kReplayTolerance = 1e-9;

/// When `episode` lacks its transitions (has_transitions() false), replays its actions in
/// `world` from its first state (the noise stream seeded with its seed, as rollout() does) and,
/// only if every replayed state matches the recorded next state within `tolerance`, fills the
/// final state, the rewards and terminated/truncated from the replay. Returns whether the
/// episode has transitions afterwards. An episode whose recorded actions are not what the world
/// executed (DART's noise, a human recording in another simulator) does not replay and is left
/// as it was.
bool recover_transitions(Episode& episode, const WorldConfig& world, double tolerance = kReplayTolerance);

/// recover_transitions for every episode; returns the names of those still without transitions.
std::vector<std::string> recover_transitions(std::vector<Episode>& episodes, const WorldConfig& world,
                                             double tolerance = kReplayTolerance);

/// The outcome judge over recorded states and the state after the last action, each placed in
/// `world` (no simulation, no settling): for recordings and files that do not carry our outcome.
/// steps is states.size().
Outcome judge_states(const std::vector<State>& states, const State& final_state, const WorldConfig& world);

}  // namespace dicestack
