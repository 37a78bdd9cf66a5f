#pragma once
// One demonstration: where it started, what was seen and done at every step, and how it ended.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/judge.hpp>
#include <dicestack/core/types.hpp>

namespace dicestack {

/// Who chose a step's action.
enum class StepSource { human, expert, policy, correction };

/// "human", "expert", "policy" or "correction".
std::string_view to_string(StepSource source);

/// Parses a StepSource; throws InputError naming the text and the accepted values.
StepSource step_source_from(std::string_view text);

/// A demonstration: T pre-action states and the T actions taken in them (DESIGN "Demonstrations").
struct Episode {
  std::string name;            ///< file stem, e.g. "episode_0007"
  std::uint64_t seed = 0;      ///< seed of the initial state (0 when unknown, e.g. human recordings)
  std::vector<State> states;   ///< state before each action; states[0] is the initial state
  std::vector<Action> actions; ///< the action applied in each state
  std::vector<StepSource> sources;  ///< who chose each action
  Outcome outcome;             ///< the judge's outcome of the whole episode
  std::string origin;          ///< where it came from (a source file, an expert's name); may be empty

  std::size_t size() const { return states.size(); }
};

/// Throws InputError naming the episode unless states, actions and sources have one equal,
/// non-zero length and every value is finite.
void check_episode(const Episode& episode);

}  // namespace dicestack
