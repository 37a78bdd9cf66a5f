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
  /// On an arm, its links' readings with each state (as many as states); empty for the floating
  /// cup. Read by maps with the "links" part.
  std::span<const ArmLinks> links = {};
  /// Step index of the current state (0 at the start).
  std::size_t t() const { return states.size() - 1; }
  const State& current() const { return states.back(); }
  const State& start() const { return states.front(); }
};

/// The widest row any map produces (a stack buffer on the hot path): the state, the arm's links,
/// the clock, the whole start, the previous state and the dice frame's origin.
inline constexpr std::size_t kMaxFeatureWidth = 80;
/// The most answers a regressor gives: the arm's four joint torques.
inline constexpr std::size_t kMaxOutputWidth = kJointCount;

/// What a policy's regressor answers: the action itself (the cup's velocity change, the paper's
/// impulse), the cup velocity the action is to set (the action is then that velocity minus
/// the cup's velocity now), or the cup pose r a servo pulls the cup to (the action sets the
/// velocity kPositionGain (r - p) on x, y and angle). An expert that tracks a reference by
/// cancelling the cup's velocity error gives labels that hold the noise of the last step; as
/// velocities they are smooth; as poses, for a tracker of the same gain, the same wherever the
/// cup is (so a learner's errors do not add up into a drift). On an arm, a policy may answer the
/// joint torques its four joints hold through the step instead (the joint_torque controller), or
/// a cup pose as "/position" does, with the posture's acceleration, that a fixed
/// operational-space law (arm_torques over the control step, the default world's arm) turns into
/// those torques once per step ("/osc"): a pose is one per step wherever the arm is, a torque is
/// not.
enum class ActionTarget { impulse, velocity, position, torque, osc };

/// What a feature map is made of: its name, read part by part. The grammar of a name
/// (docs/learners.md, "Feature-map names"):
///
///     NAME   := INPUTS [TARGET] [TIMING]
///     INPUTS := PART ("+" PART)*     each part at most once, in the order below
///     PART   := "state" | "cup"       the current state, or only the cup's six numbers of it
///             | "clock"               the step index t
///             | START ["@dice"]       "@dice": every x measured from the start's mean die x
///             | "history"             the previous state (the start repeated at t = 0)
///             | "retry"               the clock and the start restart with each attempt
///     START  := "start"               the start's cup x and mean die x
///             | "start_state"         the whole start state
///     TARGET := "/velocity" | "/position"   the regressor answers a cup velocity or a pose
///             | "/torque"                 the arm's four joint torques (no TIMING)
///             | "/osc"                    a pose and posture servoed to by held joint torques (needs links, no TIMING)
///     TIMING := "/ahead" | "/landing"       under delays, the cup where the action lands
///
/// A map with no current-state part is open loop. "retry" needs a clock or a start to restart.
struct FeatureSpec {
  enum class Current { none, state, cup };
  enum class Start { none, summary, whole };
  enum class Timing { now, ahead, landing };
  Current current = Current::none;
  bool links = false;       ///< "links"
  bool clock = false;
  Start start = Start::none;
  bool dice_frame = false;  ///< "@dice": x measured from the start's mean die x, that origin the last column
  bool previous = false;    ///< "history"
  bool restart = false;     ///< "retry": the clock and the start restart at each attempt (attempt_start)
  ActionTarget target = ActionTarget::impulse;
  Timing timing = Timing::now;
  bool operator==(const FeatureSpec&) const = default;
};

/// Reads a map's name. Throws ConfigError naming the name and the part that breaks the grammar
/// (unknown, repeated, out of order, or a suffix that does not belong there).
FeatureSpec parse_feature_spec(std::string_view name);
/// The name of `spec`: parse_feature_spec's inverse, so a model file's name reads back the same.
std::string to_string(const FeatureSpec& spec);
/// The map for a policy in joint torques made from map `name`: its inputs, the arm's links
/// added, answering a pose the operational-space law turns into torques ("/osc", no timing).
/// "state+clock/position" gives "state+links+clock/osc". Throws ConfigError as parse_feature_spec.
std::string torque_map_name(std::string_view name);

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
  /// Throws InputError for a map that reads the arm's links when the history has none.
  virtual void compute(const History& history, std::span<double> out) const = 0;
  /// What the regressor's outputs are (default: the action).
  virtual ActionTarget target() const { return ActionTarget::impulse; }
  /// The controller its actions are for: joint_torque for a "/torque" or "/osc" map, else cup.
  ActionKind action_kind() const {
    return target() == ActionTarget::torque || target() == ActionTarget::osc ? ActionKind::joint_torque : ActionKind::cup;
  }
  /// The names of the regressor's answers: the four torques of a "/torque" map, else the cup's
  /// three numbers, and for an "/osc" map the posture's acceleration after them.
  std::span<const std::string_view> answer_names() const;
  /// The regressor's answers per row (3, or 4: torques, or an "/osc" map's pose and posture).
  std::size_t outputs() const { return answer_names().size(); }
  /// True for a map that reads the arm's links (History::links): it runs only on an arm.
  virtual bool reads_links() const { return false; }

  /// True for a map that acts for the moment its action lands (kAheadSuffix, kLandingSuffix).
  virtual bool ahead() const { return false; }

  /// True for a map whose clock and start restart with each attempt (attempt_start: "+retry").
  virtual bool attempts() const { return false; }

  /// Where x is measured from in this map's rows and pose answers (0: the world's origin).
  virtual double origin_x(const History&) const { return 0.0; }

  /// The regressor's answer for `action` taken after `history`: a training label (outputs()
  /// values). Throws InputError when the action is for another controller than action_kind().
  void label(const History& history, const Action& action, std::span<double> out) const;
  /// The action for the regressor's answer `output` after `history`. Hot path.
  Action action(const History& history, std::span<const double> output) const;
};

/// The state the world is in when an action chosen after `history` lands: the current state
/// with the cup moved on through history.unseen then history.pending as it moves free in the
/// nominal world (each action a velocity change, then gravity, no contact). The dice stay as
/// shown. The current state itself when nothing is unseen or pending.
State cup_ahead(const History& history);

/// Throws ConfigError if `map` cannot run in `world`: an "/ahead" map whose physics (gravity,
/// control step, substeps) is not the default world's, which cup_ahead() moves the cup in; a
/// map that reads the arm's links or answers joint torques, in a world without the arm; an
/// "/osc" map on an arm or a control step other than the default world's, whose law it carries.
void check_map_world(const FeatureMap& map, const WorldConfig& world);

/// The map a name describes (FeatureSpec's grammar), e.g. "state+clock+start_state@dice+retry/position",
/// dart's default with the tracker. Every valid name is a map; the same name, the same object.
/// "/ahead" maps show cup_ahead() instead of the current cup and keep the clock of the choices
/// made so far; "/landing" maps show the clock of the step the action lands at too (for a
/// policy trained under delays drawn per episode). Throws ConfigError as parse_feature_spec.
const FeatureMap& feature_map(std::string_view name);

/// The suffix of a map whose regressor answers the cup velocity to set (ActionTarget::velocity).
inline constexpr std::string_view kVelocityTargetSuffix = "/velocity";
/// The suffix of a map whose regressor answers the cup pose to servo to (ActionTarget::position).
inline constexpr std::string_view kPositionTargetSuffix = "/position";
/// The servo gain of "/position" maps, 1/s: the tracker's default gain, so that its labels are
/// one pose per step wherever the cup is.
inline constexpr double kPositionGain = 10.0;

/// The suffix of a map whose regressor answers the arm's joint torques (ActionTarget::torque).
inline constexpr std::string_view kTorqueTargetSuffix = "/torque";

/// The suffix of a map whose regressor answers the cup pose held joint torques servo to (ActionTarget::osc).
inline constexpr std::string_view kOscTargetSuffix = "/osc";

/// The suffix of a map that acts for the moment its action lands (FeatureMap::ahead()).
inline constexpr std::string_view kAheadSuffix = "/ahead";
/// The suffix of an "/ahead" map whose clock is the step its action lands at.
inline constexpr std::string_view kLandingSuffix = "/landing";

/// The maps `dicestack learners` lists, in its order: eleven input sets, each with every target
/// and timing (99 names). feature_map() accepts any other name the grammar allows too.
std::vector<std::string> feature_map_names();

/// The "state" map: the default of every learner that does not name one.
const FeatureMap& state_features();

}  // namespace dicestack
