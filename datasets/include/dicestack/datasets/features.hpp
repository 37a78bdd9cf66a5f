#pragma once
// Observations: what a learned policy's regressor sees. A feature map turns what an episode has
// shown the policy so far (its states, the step index, its start) into the regressor's input
// row. Maps are named and versioned; a model file stores its map, so training, evaluation,
// DAgger, DaD, the leaderboard and render all compute the same row. A map never reads anything
// computed inside an expert (a plan, its clock, its parameters): only what the world showed.
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// What an episode has shown a policy when it acts at step t: the states before each action,
/// states[0] (the start) .. states[t] (the current one), and the t actions the world applied.
struct History {
  std::span<const State> states;   ///< t + 1 states; never empty
  /// t actions (may be empty when the caller does not track them). In rollouts the actions the
  /// world applied; in training rows (make_dataset) the recorded labels, which differ under DART
  /// noise and DAgger: no built-in map reads them for that reason.
  std::span<const Action> actions;
  /// Under an action delay, what was chosen earlier and runs before the action chosen
  /// now, in the order it runs (zeros for the steps before the first choice lands); empty
  /// without a delay. An expert simulates through it to the state its action lands in.
  std::span<const Action> pending = {};
  /// Under an observation delay, what ran (as chosen, before noise) since the state shown:
  /// states.back() is that many steps old. Empty without a delay.
  std::span<const Action> unseen = {};
  /// Step index of the current state (0 at the start).
  std::size_t t() const { return states.size() - 1; }
  const State& current() const { return states.back(); }
  const State& start() const { return states.front(); }
};

/// The widest row any built-in map produces (a stack buffer on the hot path).
inline constexpr std::size_t kMaxFeatureWidth = 64;

/// What a policy's regressor answers: the action itself (the cup's velocity change, the paper's
/// impulse), the cup velocity the action is to set (the action is then that velocity minus
/// the cup's velocity now), or the cup pose r a servo pulls the cup to (the action sets the
/// velocity kPositionGain (r - p) on x, y and angle). An expert that tracks a reference by
/// cancelling the cup's velocity error gives labels that hold the noise of the last step; as
/// velocities they are smooth; as poses, for a tracker of the same gain, the same wherever the
/// cup is (so a learner's errors do not add up into a drift).
enum class ActionTarget { impulse, velocity, position };

/// A named, versioned map from a History to one input row, and from the regressor's answer to
/// an action. Immutable; thread-safe.
class FeatureMap {
 public:
  virtual ~FeatureMap() = default;
  /// The name `train --features` and model files use, e.g. "state+clock+start".
  virtual std::string name() const = 0;
  /// Bumped whenever the map's output for a history changes; stored in model files.
  virtual int version() const = 0;
  /// Inputs per row (<= kMaxFeatureWidth).
  virtual std::size_t width() const = 0;
  /// One name per input column (the state names first).
  virtual std::vector<std::string> column_names() const = 0;
  /// One line for listings.
  virtual std::string description() const = 0;
  /// Writes the row for `history` into `out` (width() values). Hot path: never allocates.
  virtual void compute(const History& history, std::span<double> out) const = 0;
  /// What the regressor's kActionDim outputs are (default: the action).
  virtual ActionTarget target() const { return ActionTarget::impulse; }

  /// True for a map that acts for the moment its action lands (kAheadSuffix, kLandingSuffix).
  virtual bool ahead() const { return false; }

  /// True for a map whose clock and start restart with each attempt (attempt_start: "+retry").
  virtual bool attempts() const { return false; }

  /// Where x is measured from in this map's rows and pose answers (0: the world's origin).
  virtual double origin_x(const History&) const { return 0.0; }

  /// The regressor's answer for `action` taken after `history`: a training label.
  void label(const History& history, const Action& action, std::span<double> out) const;
  /// The action for the regressor's answer `output` after `history`. Hot path.
  Action action(const History& history, std::span<const double> output) const;
};

/// The state the world is in when an action chosen after `history` lands: the current state
/// with the cup moved on through history.unseen then history.pending as it moves free in the
/// nominal world (each action a velocity change, then gravity, no contact). The dice stay as
/// shown. The current state itself when nothing is unseen or pending.
State cup_ahead(const History& history);

/// Throws ConfigError if `map` is an "/ahead" map and `world`'s physics (gravity, control step,
/// substeps) is not the default world's, which cup_ahead() moves the cup in.
void check_ahead_world(const FeatureMap& map, const WorldConfig& world);

/// The built-in maps, by name:
///  - "state": the 24 state numbers (the paper's input; what every model before format 2 used)
///  - "state+clock": + the step index t (control steps since the start)
///  - "state+clock+start": + t, the start's cup x and the start's mean die x
///  - "state+history": + the previous state (the start repeated at t = 0): the last step's
///    velocity changes, which carry the previous action
///  - "state+clock+start_state": + t and the whole start state
///  - "clock+start_state", "cup+clock+start_state": open loop, and feedback on the cup alone
///  - "state+clock+start_state@dice", "clock+start_state@dice": every x measured from the
///    start's mean die x, that origin a last column (origin_x()): a recording the tracker moves
///    to each start is then the same rows and poses for every start
///  - "state+clock+start_state+retry", "state+clock+start_state@dice+retry": the clock and the
///    start (and the frame's origin) restart where a failed attempt has come to rest
///    (attempt_start, judged in the default world), for an expert that then tries again
///    (ExpertConfig::retry): its second attempt is then the rows of a first one
/// Each also as NAME + "/velocity" (kVelocityTargetSuffix): the same inputs, the regressor
/// answering the cup velocity to set, and as NAME + "/position" (kPositionTargetSuffix):
/// answering the pose to servo the cup to ("state+clock+start_state@dice+retry/position" is dart's
/// default with the tracker).
/// Each of these also as NAME + "/ahead" (kAheadSuffix): under delays, the row shows
/// cup_ahead() instead of the current cup (with no delay, the same rows as NAME). The clock
/// stays t, the choices made so far: a policy's episode is then the nominal one, d steps late.
/// (Shown the step its action lands at, a policy trained without delay meets at t = d a cup
/// that has not moved yet, which it never saw: measured, docs/robustness.md.)
/// And as NAME + "/landing" (kLandingSuffix): the "/ahead" row with the clock of the step the
/// action lands at (t plus the pending actions): for a policy trained under delays drawn per
/// episode, which then reads one clock for the cup it meets, whatever the delay.
/// Throws ConfigError for another name, listing these.
const FeatureMap& feature_map(std::string_view name);

/// The suffix of a map whose regressor answers the cup velocity to set (ActionTarget::velocity).
inline constexpr std::string_view kVelocityTargetSuffix = "/velocity";
/// The suffix of a map whose regressor answers the cup pose to servo to (ActionTarget::position).
inline constexpr std::string_view kPositionTargetSuffix = "/position";
/// The servo gain of "/position" maps, 1/s: the tracker's default gain, so that its labels are
/// one pose per step wherever the cup is.
inline constexpr double kPositionGain = 10.0;

/// The suffix of a map that acts for the moment its action lands (FeatureMap::ahead()).
inline constexpr std::string_view kAheadSuffix = "/ahead";
/// The suffix of an "/ahead" map whose clock is the step its action lands at.
inline constexpr std::string_view kLandingSuffix = "/landing";

/// Names feature_map() accepts, in listing order.
std::vector<std::string> feature_map_names();

/// The "state" map: the default of every learner that does not name one.
const FeatureMap& state_features();

}  // namespace dicestack
