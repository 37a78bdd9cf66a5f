#pragma once
// The open-loop question on the arm: a fixed oscillation of the arm's joints (an offset,
// amplitude, frequency and phase per joint, and a time to stop), which sees the arm's own
// joints and never the cup or the dice, searched with CMA-ES over a set of starts. A joint
// servo (computed torque: the pattern's acceleration plus a critically damped PD, through the
// chain's dynamics) holds each joint on its pattern through the joint_torque controller.
// docs/arm.md, "The open-loop question".
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/judge.hpp>

namespace dicestack {

/// Each joint's angle (relative, as the world config's joint limits) follows
///   start + offset * min(1, t / 1 s) + amplitude * (sin(2 pi frequency t + phase) - sin(phase))
/// until `stop`, then holds where the pattern was at `stop`.
struct JointOscillation {
  std::array<double, 4> offset{};     ///< rad, eased in over the first second
  std::array<double, 4> amplitude{};  ///< rad
  std::array<double, 4> frequency{};  ///< Hz
  std::array<double, 4> phase{};      ///< rad
  double stop = 0.0;                  ///< s

  static constexpr std::size_t kParameters = 17;
  /// The pattern of a search point (offset 0.5 x, amplitude 0.5 |x|, frequency |x| Hz, phase
  /// pi x, stop 4 + 4 x s, at least 0): x = 0 is the arm held still.
  static JointOscillation from_search(const double* x);
  std::string to_text() const;  ///< one line per joint, then the stop
};

/// The torques that hold `world`'s arm on `pattern` at control step `t`, from the joint angles
/// the episode started with. Throws InputError if the world's embodiment is not the arm.
Action oscillation_torques(const World& world, const JointOscillation& pattern, const std::array<double, 4>& start,
                           int t);

/// The arm's four joint angles now (relative: the shoulder's absolute, each other one's link
/// minus the link before it; the wrist's the cup's angle minus the last link's).
std::array<double, 4> arm_joint_angles(const World& world);

/// What one pattern did from one start: eq. 6's cost (minus the episode's summed reward) and the
/// judge's outcome.
struct OscillationEpisode {
  double cost = 0.0;
  Outcome outcome;
  /// What the search minimises: eq. 6's cost, less a third for each die the cup held at once,
  /// less 2 for a realistic success, plus 1 for wall contact. Eq. 6 alone is flat around the
  /// arm held still (the dice stay in their row), where CMA-ES stops.
  double search_cost() const;
};

/// Runs `pattern` from `start` until a realistic success has held (the episode's end under
/// evaluate) or the world's episode.max_steps, the physics noise (if any) seeded by `seed`.
OscillationEpisode run_oscillation(DiceEnv& env, const JointOscillation& pattern, const State& start, std::uint64_t seed);

struct OscillationSearch {
  int starts = 8;             ///< training starts each evaluation runs (training_start_seed 0..starts-1)
  int evaluations = 3000;     ///< CMA-ES's budget
  double sigma0 = 0.5;        ///< its first step, in search units
  std::uint64_t seed = 0;     ///< the training starts' and CMA-ES's seed
  int threads = 0;            ///< 0: every core; the result does not depend on it
};

struct OscillationResult {
  JointOscillation best;
  double best_cost = 0.0;     ///< its mean cost over the training starts
  int evaluations = 0;
};

/// Minimises the mean search_cost over the training starts of `world` (its start distribution:
/// with_starts(world, "paper") for the paper's). `progress` (may be empty) gets the evaluations
/// done and the best cost so far. Throws ConfigError unless the world's embodiment is the arm.
OscillationResult search_oscillation(const WorldConfig& world, const OscillationSearch& search,
                                     const std::function<void(int, double)>& progress = {});

}  // namespace dicestack
