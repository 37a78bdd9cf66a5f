#pragma once
// DaD's corrector (paper eq. 11): from the world a policy drifted into, find the next w actions
// whose simulated states follow the demonstration's next w states (all 24 numbers, as the paper
// wrote it; the dice and the cup's velocity, as the paper's code compared them) or its cup path
// alone (no cup motion brings bounced dice back onto their recorded states). Any method of
// core/action_sequence.hpp: CMA-ES (ours), pagmo's differential evolution, basin hopping,
// Bayesian optimisation; or "track": the tracker's feedback law steering the cup back onto the
// recorded path, no search.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/env.hpp>

namespace dicestack {

/// What a window's corrections aim at.
enum class CorrectionTarget {
  state,  ///< the demonstration's whole states (eq. 11 as the paper wrote it)
  cup,    ///< the demonstration's cup pose (x, y, angle) alone
  dice,   ///< the dice' poses and velocities and the cup's velocity (state_distance: the paper's code)
};

/// One window to correct.
struct CorrectionProblem {
  EnvSnapshot start;           ///< the world where the window begins (the policy's, drifted)
  std::vector<State> target;   ///< the demonstration's states after each of the w steps
  std::vector<Action> warm;    ///< the policy's own w actions from `start`: the search starts here
  CorrectionTarget aim = CorrectionTarget::state;
  /// "track": the demonstration's states and actions at the window's own steps (the state each
  /// action was taken in), which the feedback law follows.
  std::vector<State> reference;
  std::vector<Action> reference_actions;
  /// What the window's actions are: the cup's velocity changes, or the arm's joint torques
  /// ("track" alone: it tells each of its cup actions in torques, core/tracker.hpp's told_in_torques).
  ActionKind action_kind = ActionKind::cup;
};

/// The best actions found and the trajectory they produce.
struct Correction {
  std::vector<State> states;    ///< the state before each corrected action (states[0] is start's)
  std::vector<Action> actions;  ///< in the world's units, within its limits: labels as they are applied
  std::vector<ArmLinks> links;  ///< on the arm, its links before each corrected action (empty for the floating cup)
  double cost = 0.0;            ///< eq. 11: sum over the window of the squared scaled distance
  double warm_cost = 0.0;       ///< the same for the policy's own actions
  int evaluations = 0;          ///< window simulations spent
};

/// Squared scaled distance (all 24 dimensions, the cup's 3 or state_distance's 21, by aim) summed
/// over the window when `actions` are applied from `problem.start`; fills `states` (may be null)
/// with the states before each action, and on the arm `links` (may be null) with its links then.
double window_cost(DiceEnv& env, const CorrectionProblem& problem, const std::vector<Action>& actions,
                   std::vector<State>* states = nullptr, std::vector<ArmLinks>* links = nullptr);

/// Searches in the optimisers' scaled action space (x = action / ActionConfig::scale), clipped
/// to the world's limits.
class Corrector {
 public:
  virtual ~Corrector() = default;
  /// `env` is scratch: its episode is overwritten. Never returns worse than the warm start
  /// (unless CorrectorOptions::random_start). Throws InputError for a problem in joint torques
  /// unless it is "track" (a search over torque sequences is not built).
  virtual Correction correct(DiceEnv& env, const CorrectionProblem& problem, std::uint64_t seed) const = 0;
};

struct CorrectorOptions {
  int iterations = 50;   ///< generations (basinhop, bayes: iterations x population evaluations)
  double sigma0 = 0.25;  ///< initial spread in scaled action units
  int population = 0;    ///< 0: pycma's 4 + floor(3 ln n)
  double gain = 10.0;    ///< "track": feedback gain on the cup's pose, 1/s
  int evaluations = 0;   ///< a budget of window simulations instead of `iterations` (0: iterations decide)
  /// Start each search at a point drawn uniformly in [-1, 1]^n from its seed and keep its best
  /// even where the policy's own actions score better (the paper's code); false: start at the
  /// policy's actions and never return worse.
  bool random_start = false;
};

/// The correctors' names: cmaes, de, basinhop, bayes, track.
std::vector<std::string> corrector_names();

/// One of corrector_names(); throws ConfigError for another name.
std::unique_ptr<Corrector> make_corrector(std::string_view name, const CorrectorOptions& options);

}  // namespace dicestack
