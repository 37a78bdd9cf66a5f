#pragma once
// Perturbed worlds: named factors, each with a magnitude, drawn per episode from the
// episode's seed. A Perturbation says how far each factor may go; a PerturbationDraw is what
// one episode got. Physics and starts change the world; actuation and sensing change what the
// rollout executes and what the policy sees (learners/evaluate.hpp). docs/robustness.md has the
// levels' table.
#include <cstdint>
#include <deque>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/rng.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// How far each factor may go; every field 0 is the nominal world ("none").
struct Perturbation {
  // Physics: each coefficient or mass is scaled by U(1 - a, 1 + a) (friction: dice, cup and
  // table drawn apart); gravity's y gets N(0, sigma) m/s^2 added.
  double friction = 0.0;   ///< a, in [0, 1)
  double dice_mass = 0.0;  ///< a, in [0, 1)
  double cup_mass = 0.0;   ///< a, in [0, 1)
  double gravity = 0.0;    ///< sigma, m/s^2, in [0, 2]
  // Actuation: each executed action gets N(0, noise) per step plus a per-episode bias
  // N(0, bias), both as fractions of its scale (action.scale for the cup's actions, the arm's
  // torque limits for joint torques); it is applied `delay` steps late.
  double action_noise = 0.0;  ///< in [0, 10]
  double action_bias = 0.0;   ///< in [0, 10]
  int action_delay = 0;       ///< steps, in [0, 100]
  // Sensing: the policy sees each state component plus N(0, noise x its spread)
  // (observation_spread()), `delay` steps late.
  double observation_noise = 0.0;  ///< in [0, 10]
  int observation_delay = 0;       ///< steps, in [0, 100]
  // Domain randomisation over delays: each episode's action and observation delays drawn
  // uniformly from 0 to the values above (format version 2), so one policy meets them all.
  bool delays_drawn = false;
  // Starts: randomization.shift, cup_lift and cup_tilt multiplied by (1 + this). The dice's
  // jitter stays: the default dice start one side plus twice the jitter apart already.
  double start_widening = 0.0;  ///< in [0, 3]

  bool operator==(const Perturbation&) const = default;
  bool nominal() const { return *this == Perturbation{}; }
};

/// The factors by name, in table order: friction, dice_mass, cup_mass, gravity, action_noise
/// (with its bias), action_delay, observation_noise, observation_delay, start.
const std::vector<std::string>& perturbation_factors();
/// The levels by name: none, easy, medium, hard.
const std::vector<std::string>& perturbation_levels();

/// Every factor at `level` ("none", "easy", "medium" or "hard"); throws ConfigError naming the
/// levels otherwise.
Perturbation perturbation_level(std::string_view level);
/// Only `factor` at `level`, the rest nominal; throws ConfigError naming the factors or levels.
Perturbation perturbation_factor(std::string_view factor, std::string_view level);

/// Throws ConfigError naming the first field out of its range (`source` prefixes the message),
/// and if a delay would not leave `max_steps` room to act.
void validate(const Perturbation& p, const WorldConfig& world, const std::string& source = "perturbation");

/// "none", "easy", "medium", "hard", or a file written by perturbation_to_json (format
/// "dicestack-perturbation", versions 1 and 2). Throws ConfigError / InputError naming the file
/// and field.
Perturbation load_perturbation(const std::string& level_or_file, const WorldConfig& world);
std::string perturbation_to_json(const Perturbation& p);
/// The fields that are on, as "friction 0.3, action_delay 3" ("none" when nominal): for
/// provenance and headers.
std::string perturbation_summary(const Perturbation& p);
Perturbation perturbation_from_json(std::string_view text, const std::string& source, const WorldConfig& world);

/// The longest delay, in control steps, of either kind (and shorter than the episode).
inline constexpr int kMaxActionDelay = 100;

/// One key of a perturbation file, as its reference page lists it.
struct PerturbationKey {
  std::string name;
  std::string type;  ///< "number", "integer" or "boolean"
  std::string range;
  std::string meaning;
};
/// The keys of a perturbation file, in file order: the table its reader and checks use.
std::vector<PerturbationKey> perturbation_keys();

/// What one episode got.
struct PerturbationDraw {
  WorldConfig world;        ///< the world it runs in (physics and start ranges changed)
  Action action_bias{0.0, 0.0, 0.0};  ///< world units, added to every executed cup action
  Action action_noise{0.0, 0.0, 0.0};  ///< std per step, world units
  /// The same for joint-torque actions, N m: drawn after everything else (so a cup's draws are
  /// as before), from the arm's torque limits.
  Action torque_bias = Action::zeros(ActionKind::joint_torque);
  Action torque_noise = Action::zeros(ActionKind::joint_torque);
  int action_delay = 0;
  State observation_noise{};  ///< std per state component
  int observation_delay = 0;
  std::uint64_t noise_seed = 0;  ///< the stream of the per-step noises
  bool physics = false;     ///< world differs from the nominal one (an environment of its own)
  bool acts = false;        ///< actuation or sensing is perturbed
};

/// The draw for the episode of `episode_seed`: a pure function of the perturbation, the world
/// and the seed (the same on any thread or rank). With a nominal perturbation, the world
/// unchanged and nothing else set.
PerturbationDraw draw_perturbation(const Perturbation& p, const WorldConfig& world, std::uint64_t episode_seed);

/// The values an episode drew, as a JSON object (the per-episode "perturbation" of saved sets
/// and of the Python environment's info; docs/formats.md): frictions, masses, gravity, the action
/// bias and noise, the delays, the observation noise and the start ranges; for an episode whose
/// `actions` are joint torques, their bias and noise too.
std::string draw_to_json(const PerturbationDraw& draw, ActionKind actions = ActionKind::cup);

/// The actuation and sensing of a draw saved by draw_to_json (what a PerturbedChannel needs to
/// replay an episode's observations: the noises' std, the bias, the delays and the noise seed);
/// the world is left the default, and a field left out is nominal. Throws InputError naming
/// `source` and the field out of range, or when there is observation noise and no noise seed.
PerturbationDraw channel_draw_from_json(std::string_view text, const std::string& source);

/// What a perturbed episode's policy sees and what the world executes (the draw's sensing and
/// actuation), step by step; rollout() and the Python environment share it, so both give the
/// same episodes.
class PerturbedChannel {
 public:
  /// `actions`: the kind the policy answers in (what runs while nothing has been chosen).
  explicit PerturbedChannel(const PerturbationDraw& draw, ActionKind actions = ActionKind::cup);
  /// The observation at the step whose true state is `state` (call once per state, in order,
  /// from the start): the state observation_delay steps ago (the start before then), plus noise.
  State observe(const State& state);
  /// What runs at this step, given what the policy chose now: its choice action_delay steps ago
  /// (nothing before then), plus the bias and this step's noise of its kind. Throws InputError
  /// for a choice of another kind than the channel's.
  Action execute(const Action& chosen);
  /// What runs at the next action_delay steps before the next choice does (before bias and
  /// noise), in order: the choices not yet run, zeros before the first. Empty without a delay.
  const std::deque<Action>& pending() const { return chosen_; }
  /// What ran (as chosen, before bias and noise) since the state observe() last showed, in
  /// order. Empty without an observation delay.
  const std::deque<Action>& unseen() const { return ran_; }

 private:
  PerturbationDraw draw_;
  Rng noise_;
  std::deque<State> states_;
  std::deque<Action> chosen_;
  std::deque<Action> ran_;
  ActionKind actions_;
};

/// The typical spread of each state component (positions m, angles rad, velocities), the unit
/// of observation noise.
const State& observation_spread();

}  // namespace dicestack
