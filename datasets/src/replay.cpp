#include <dicestack/datasets/replay.hpp>

#include <algorithm>
#include <cmath>

#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>

namespace dicestack {

bool recover_transitions(Episode& e, const WorldConfig& world, double tolerance) {
  if (e.has_transitions()) return true;
  if (e.states.empty()) return false;
  WorldConfig w = world;
  w.episode.max_steps = std::max(w.episode.max_steps, static_cast<int>(e.size()));  // never cut a replay short
  DiceEnv env(w);
  env.reset_to(e.states.front(), e.seed);
  const State goal = goal_state(world);
  std::vector<double> rewards;
  StepResult r;
  for (std::size_t t = 0; t < e.size(); ++t) {
    r = env.step(e.actions[t]);
    // Rewards follow the recording's world (its time limit), not the stretched one.
    rewards.push_back(step_reward(r.observation, r.info.t, world, goal));
    if (t + 1 < e.size()) {
      for (std::size_t k = 0; k < kStateDim; ++k)
        if (!(std::abs(r.observation[k] - e.states[t + 1][k]) <= tolerance)) return false;
      if (r.terminated) return false;  // the world would have ended the episode here
    }
  }
  e.final_state = r.observation;
  e.rewards = std::move(rewards);
  e.terminated = r.terminated;
  e.truncated = !r.terminated;
  return true;
}

std::vector<std::string> recover_transitions(std::vector<Episode>& episodes, const WorldConfig& world, double tolerance) {
  std::vector<std::string> missing;
  for (auto& e : episodes)
    if (!recover_transitions(e, world, tolerance)) missing.push_back(e.name);
  return missing;
}

Outcome judge_states(const std::vector<State>& states, const State& final_state, const WorldConfig& world) {
  Outcome o;
  World probe(world);
  for (const State& s : states) {
    probe.set_state(s);
    observe(o, s, probe.touching_walls(), world);
  }
  probe.set_state(final_state);
  observe(o, final_state, probe.touching_walls(), world);
  o.steps = static_cast<int>(states.size());
  return o;
}

}  // namespace dicestack
