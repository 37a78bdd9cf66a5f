#pragma once
// Automatic experts: controllers that stack the dice the realistic way (paper III-C, no wall)
// from any state, to generate demonstrations and to answer DAgger's queries.
//
// Both experts drive the cup the way the human recordings do (data/cupdice: every one of the
// 17,603 legacy frames and all three final ones keep the cup mouth-down): the cup hovers
// mouth-down a few centimetres above the table with the dice caged under it, swings left and
// right with its mouth aimed at a point below the table's centre (the humans' mouse-aim at the
// bottom of the screen), so the walls scoop the dice up and press them into a column against
// one side, then stops, and the column slides down onto the table. See docs/expert.md.
//
// Target dicestack::experts (core/experts/: this header, the experts and the swing plan). Where a
// Policy is expected (rollouts, DAgger, DART), an expert is wrapped in ExpertPolicy
// (learners/policy.hpp); docs/architecture.md says why the adapter lives there.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/tracker.hpp>

namespace dicestack {

/// One swing plan: a reference trajectory for the cup that a feedback controller tracks.
/// Defaults are the tuned nominal plan (docs/expert.md); distances are metres, times control steps.
struct SwingParams {
  double first_direction = 1.0;   ///< sign of the first swing: +1 right, -1 left
  double amplitude = 2.203;       ///< swing extremes sit this far from the swing centre, m (clamped off the walls)
  double half_period = 23.422;    ///< duration of one left-to-right swing, steps (the first is 0.6 of it; rounded)
  int half_swings = 6;            ///< number of swings before the stop, >= 0
  double pivot_depth = 2.857;     ///< the mouth aims at a point this far below the cup's centre of mass, m
  double clearance = 0.003;       ///< gap between the cup's lowest point and the table, m
  double centre_offset = -0.157;  ///< swing centre relative to the dice' mean x, m
  double stop_offset = -0.407;    ///< where the cup stops, relative to the swing centre, m
  double stop_speed = 3.122;      ///< the last swing reaches the stop point at this speed and halts in one step, m/s
  double final_duration = 27.731; ///< duration of the last swing, steps (rounded: the stop falls on a control step)
  double end_tilt = -0.138;       ///< tilt from mouth-down the cup turns to after the stop, rad
  double tilt_time = 4.520;       ///< time constant of that turn, steps
  double settle_steps = 30.0;     ///< after the stop, the cup holds still this long while the column lands, steps
  double release_steps = 20.0;    ///< then it centres itself over the dice and turns upright, steps
  double lift_speed = 1.0;        ///< then it rises straight up at this speed, m/s (as the humans did)
  double lift_height = 1.2;       ///< until it is this much higher than it hovered, m
};

/// Settings of every expert; make_expert() reads the fields its expert uses.
struct ExpertConfig {
  SwingParams swing;              ///< the nominal plan ("scripted" follows it, "mpc" searches around it)
  double gain = 10.0;             ///< feedback gain of the cup's pose tracking, 1/s
  double wall_margin = 0.10;      ///< the plan keeps the cup this far from the side walls, m
  int search_budget = 64;         ///< "mpc": most plans simulated when it has no plan for this episode, >= 1
  int replan_budget = 16;         ///< "mpc": most plans simulated when a state leaves its prediction, >= 1
  /// "mpc": off its predicted trajectory, re-check and re-search the plan at most once per this
  /// many steps and follow the current plan's feedback in between (cheap DAgger labels), >= 1.
  int replan_interval = 10;
  /// "mpc": false chooses the plan once, at the episode's first step, and only tracks it after:
  /// its actions are then a function of the start, the step and the state (DART's labels).
  bool replan = true;
  double search_spread = 0.03;    ///< "mpc": std of a plan's perturbation, as a fraction of each parameter's range
  /// "mpc": a plan that succeeds is also simulated this many times with executed-action noise of
  /// std robust_noise x action.scale, and chosen only if all of these succeed too (else the
  /// success with most): plans robust to a learner's errors. 0: the first success.
  int robust_trials = 0;
  double robust_noise = 0.1;
  /// "mpc" and "tracker": try again. When a failed attempt has come to rest (attempt_start,
  /// judged in the default world as the "+retry" feature maps judge it), start afresh from that
  /// state as from a start: a new plan, or a path chosen anew. Needs act() at every step.
  bool retry = false;
  /// "tracker": the recordings it follows (required; built once and shared by every copy). Its
  /// TrackerConfig is the one the Recordings were built with.
  std::shared_ptr<const Recordings> recordings;
  /// What the expert answers: the cup's velocity change, or (on the arm) joint torques, its cup
  /// actions told in torques by in_joint_torques.
  ActionKind controller = ActionKind::cup;
};

/// A policy that may use the simulator. act() works from any state of an episode, not only
/// along its own trajectory: an expert re-derives where it is from the environment it is given.
class Expert {
 public:
  virtual ~Expert() = default;

  /// Starts a new episode; `seed` seeds every random choice the expert makes.
  void reset(std::uint64_t seed);

  /// The action for env's current state, within its limits (action_limit): the cup's (dvx, dvy,
  /// dw), or joint torques for an expert whose controller() is joint_torque.
  /// Under an action delay, `pending` holds what runs before this action lands (History's
  /// pending): the expert then acts for the state the simulator says they lead to, as a Smith
  /// predictor does (zeros if the episode ends first). With `sensed`, its feedback acts on that
  /// state (what a policy is shown: noisy, late; moved by the prediction through `pending`)
  /// while its choices and simulations still read the world: the teacher behind the policy's
  /// sensors (docs/robustness.md). Throws InputError if a state is not finite.
  Action act(const DiceEnv& env, std::span<const Action> pending = {}, const State* sensed = nullptr);

  /// The name make_expert() knows it by.
  virtual std::string name() const = 0;
  /// What its actions are: the cup's velocity change unless it answers joint torques.
  virtual ActionKind controller() const { return ActionKind::cup; }

 private:
  virtual void do_reset(std::uint64_t seed) = 0;
  /// `sensed`: the state its feedback acts on (the world's own unless act() was given another).
  virtual Action do_act(const DiceEnv& env, const State& sensed) = 0;

  std::optional<DiceEnv> ahead_;  // where `pending` leads (act with a delay)
};

/// `cup_expert` answering in joint torques, for an arm world's joint_torque controller: each cup
/// action it chooses runs through the cup controller from the environment's snapshot; the
/// torques that step held on average (World::arm_step_torques), corrected once by the chain's
/// dynamics towards the cup velocity that step ended at (arm_torque_change), are its answer.
/// Its name and every choice are the cup expert's. In a floating cup's world it throws InputError.
std::unique_ptr<Expert> in_joint_torques(std::unique_ptr<Expert> cup_expert);

/// Names make_expert() accepts, with a one-line description each.
struct ExpertInfo {
  std::string name;
  std::string description;
};
std::vector<ExpertInfo> expert_list();

/// Experts by name, in the order registered: the built-ins ("scripted", "mpc", "tracker") on
/// first use. make_expert() creates through the global one; docs/architecture.md says how to
/// add an expert.
class ExpertRegistry {
 public:
  using Factory = std::function<std::unique_ptr<Expert>(const ExpertConfig&)>;
  static ExpertRegistry& global();
  /// Throws ConfigError if the name is taken.
  void add(ExpertInfo info, Factory factory);
  /// Swaps `name`'s factory for `factory` and returns the old one (tests prove that learning from
  /// recordings builds no mpc or scripted expert). Not thread-safe against create().
  Factory replace(std::string_view name, Factory factory);
  /// Throws ConfigError for an unknown name, listing the known ones.
  std::unique_ptr<Expert> create(std::string_view name, const ExpertConfig& config) const;
  std::vector<ExpertInfo> list() const;

 private:
  struct Entry {
    ExpertInfo info;
    Factory factory;
  };
  std::vector<Entry> entries_;
};

/// Creates an expert by its command-line name: "scripted" (the swing plan, fixed parameters,
/// feedback only), "mpc" (searches swing plans in the simulator from the current state and
/// replans when the world leaves its prediction) or "tracker" (follows the recorded cup path of
/// config.recordings that its simulation from the episode's start shows to succeed; chosen
/// once per episode, tracked by feedback on the cup). "mpc" and "tracker" simulate with the
/// WorldConfig of the first environment they are given; use one expert per world. Throws
/// ConfigError for an unknown name, a bad config field, or "tracker" without recordings.
std::unique_ptr<Expert> make_expert(std::string_view name, const ExpertConfig& config = {});

/// What one expert episode did.
struct ExpertEpisode {
  Outcome outcome;
  std::vector<State> states;    ///< the state before each action (filled if requested)
  std::vector<Action> actions;  ///< the actions taken (filled if requested)
};

/// Runs `expert` in `env` from env's current state until termination or the time limit.
/// The caller starts the episode: env.reset(seed) (or reset_to) and expert.reset(seed).
ExpertEpisode run_expert_episode(Expert& expert, DiceEnv& env, bool keep_trajectory = false);

}  // namespace dicestack
