#pragma once
// One demonstration: where it started, what was seen and done at every step, and how it ended.
#include <array>
#include <cstdint>
#include <optional>
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

/// A demonstration: T pre-action states and the T actions taken in them (DESIGN "Demonstrations"),
/// and (demonstration format v2) the transitions' ends: the final state, each step's reward and
/// how the episode ended. Those are known together or not at all (has_transitions()).
struct Episode {
  std::string name;            ///< file stem, e.g. "episode_0007"
  std::uint64_t seed = 0;      ///< seed of the initial state (0 when unknown, e.g. human recordings)
  std::vector<State> states;   ///< state before each action; states[0] is the initial state
  std::vector<Action> actions; ///< the action applied in each state
  std::vector<StepSource> sources;  ///< who chose each action
  /// On an arm, its links before each action (one per state: what a policy's joint encoders
  /// read); empty for the floating cup and for recordings that did not keep them.
  std::vector<ArmLinks> links;
  /// On an arm, the torques its four joints held on average over each step, N m, shoulder first
  /// (World::arm_step_torques: what the cup controller gave, or a torque policy's own); one per
  /// action, or empty when unknown. Only beside `links`.
  std::vector<std::array<double, 4>> joint_torques;
  Outcome outcome;             ///< the judge's outcome of the whole episode
  std::string origin;          ///< where it came from (a source file, an expert's name); may be empty
  /// The state after the last action: with `states`, the T + 1 observations Minari and
  /// robomimic's next_obs need. Empty when unknown (a v1 set, or data made without a world).
  std::optional<State> final_state;
  /// On an arm, its links after the last action (with `final_state` and `links`; format v4).
  std::optional<ArmLinks> final_links;
  std::vector<double> rewards;  ///< the environment's reward of each step (DiceEnv::step); T, or empty when unknown
  bool terminated = false;      ///< the last step ended the episode in success (DiceEnv's terminated)
  bool truncated = false;       ///< it ended otherwise: time limit, a cut rollout, a stopped recording
  /// The values its perturbed world drew (draw_to_json, a JSON object; format v3), empty for the
  /// nominal world.
  std::string perturbation;

  std::size_t size() const { return states.size(); }
  /// True when final_state, rewards and the end flags are known (format v2's additions).
  bool has_transitions() const { return final_state.has_value(); }
  /// Forgets the v2 additions (final state, rewards, flags), e.g. after editing the states.
  void clear_transitions();
};

/// An upper bound of the memory an episode of `steps` steps holds while a run keeps it (states,
/// an arm's link readings, actions, sources, rewards, and a packed copy on its way between ranks): for refusing counts
/// that cannot fit (require_memory) before any work.
inline double episode_memory_bound(int steps) {
  return 2.0 * (steps + 1.0) *
             static_cast<double>(sizeof(State) + sizeof(ArmLinks) + sizeof(std::array<double, 4>) + sizeof(Action) +
                                 sizeof(StepSource) + sizeof(double)) +
         1024.0;
}

/// Throws InputError naming the episode unless states, actions and sources have one equal,
/// non-zero length (links that length too, or none; joint torques that length, and only beside
/// links, or none), its actions are of one kind (joint torques only beside links) and every
/// value is finite; with a final state, rewards has that length too,
/// the final state and rewards are finite and at most one of terminated and truncated is set;
/// without one, rewards is empty and there are no final links (which also need links).
void check_episode(const Episode& episode);

}  // namespace dicestack
