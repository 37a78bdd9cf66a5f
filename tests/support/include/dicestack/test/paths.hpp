#pragma once
// Recorded cup paths for the tracker's tests, made by the scripted expert.
#include <cstdint>
#include <string>

#include <dicestack/core/env.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/tracker.hpp>

namespace dicestack::test {

/// An episode of the scripted expert from random start `seed`, as a recorded cup path.
inline CupPath scripted_path(std::uint64_t seed, const WorldConfig& world = {}) {
  DiceEnv env(world);
  env.reset(seed);
  auto expert = make_expert("scripted");
  expert->reset(seed);
  const ExpertEpisode e = run_expert_episode(*expert, env, true);
  return {"scripted_" + std::to_string(seed), e.states, e.actions};
}

}  // namespace dicestack::test
