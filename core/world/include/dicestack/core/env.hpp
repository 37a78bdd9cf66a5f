#pragma once
// The dice-stacking task as a Gym-style environment: reset(seed) gives the first observation,
// step(action) gives observation, reward, terminated, truncated and info.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/judge.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/world.hpp>

namespace dicestack {

/// Per-step details beside the reward.
struct StepInfo {
  int t = 0;                       ///< control steps taken in this episode
  double distance = 0.0;           ///< scaled L2 distance to the goal (cost.hpp)
  bool wall_contact_step = false;  ///< a side wall or the ceiling was touched in this step
  Outcome outcome;                 ///< the judge's running outcome
};

struct StepResult {
  State observation{};
  Action applied{};        ///< the action the world applied: noise added (if configured), clipped to the limits
  double reward = 0.0;     ///< -gamma^(T - t) * distance: summed over T steps, minus eq. 6
  bool terminated = false; ///< realistic success held for judge.success_hold_steps steps
  bool truncated = false;  ///< the time limit episode.max_steps was reached
  StepInfo info;
};

/// The reward DiceEnv::step gives for arriving at `observation` after `steps` control steps of
/// an episode: -gamma^max(0, episode.max_steps - steps) * state_distance(observation, goal)
/// (cost.hpp); summed over an episode of episode.max_steps steps it is minus eq. 6. `goal` is
/// goal_state(config). Also used to fill the rewards of recordings made outside DiceEnv.
double step_reward(const State& observation, int steps, const WorldConfig& config, const State& goal);

/// Lower and upper bounds of an observation or an action.
template <std::size_t N>
struct Box {
  std::array<double, N> low{};
  std::array<double, N> high{};
};

/// An exact copy of an environment: world snapshot, step count, outcome and noise stream.
struct EnvSnapshot {
  WorldSnapshot world;
  Outcome outcome;
  Rng noise{0};
};

/// The snapshot as a self-checking byte record (WorldSnapshot::to_bytes plus the outcome and
/// the noise stream): restores exactly into an environment of the same config and build.
/// Throws InputError for an empty snapshot.
std::string to_bytes(const EnvSnapshot& snapshot);
/// Reads to_bytes()'s record; throws InputError naming what is wrong.
EnvSnapshot env_snapshot_from_bytes(std::string_view bytes);

/// One episode at a time of the dice-stacking task. Not thread-safe; use one per thread.
class DiceEnv {
 public:
  /// Throws ConfigError if `config` is invalid.
  explicit DiceEnv(const WorldConfig& config = {});

  /// Starts an episode from random_start_state(config, seed); the noise stream (if any)
  /// is seeded from `seed` too. Returns the first observation.
  State reset(std::uint64_t seed);

  /// Starts an episode from a bare state (e.g. a recorded one); `seed` seeds the noise.
  State reset_to(const State& state, std::uint64_t seed = 0);

  /// Applies `action` (plus noise if configured, then clipped to action_limit: a cup action
  /// to config.action.limit, joint torques to the arm's limits) and advances one control step.
  /// Throws InputError if the action is not finite, or holds joint torques for a floating cup.
  StepResult step(const Action& action);

  State get_state() const { return world_.state(); }
  EnvSnapshot snapshot() const;
  /// Continues bit-for-bit from `snapshot`.
  void restore(const EnvSnapshot& snapshot);

  const Outcome& outcome() const { return outcome_; }
  int t() const { return outcome_.steps; }
  const WorldConfig& config() const { return world_.config(); }
  const World& world() const { return world_; }

  /// Observation bounds: positions inside the walls, velocities below Box2D's speed cap,
  /// angles unbounded.
  Box<kStateDim> observation_space() const;
  /// Cup action bounds: +-config.action.limit.
  Box<kActionDim> action_space() const;
  /// Joint-torque action bounds (an arm's): +-config.arm.torque_limit.
  Box<kJointCount> torque_space() const;

 private:
  StepResult finish_step(bool wall);

  World world_;
  State goal_;
  Outcome outcome_;
  Rng noise_{0};
};

/// One environment per worker of parallel_for (a DiceEnv is not thread-safe), each made on its
/// worker's first use and kept for the rest of the run.
class EnvPool {
 public:
  /// `threads` as parallel_for takes it (0 = all cores). Throws ConfigError for a bad config.
  EnvPool(const WorldConfig& world, int threads);
  /// The environment of worker `worker` (parallel_for's second argument).
  DiceEnv& at(int worker);
  const WorldConfig& world() const { return world_; }

 private:
  WorldConfig world_;
  std::vector<std::optional<DiceEnv>> envs_;
};

}  // namespace dicestack
