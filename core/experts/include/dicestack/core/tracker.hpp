#pragma once
// The demonstrator made of demonstrations: recorded cup paths, moved into a start's
// frame and followed by feedback on the cup alone, chosen by simulating them from the start.
// It reads nothing but the recordings, the world and the simulator: no swing plan, no mpc.
//
// Why the cup's path and not the actions: the task is open-loop in the cup's path, not in the
// actions. A recording's actions replayed in another world (or from a start 1 cm away) lose the
// dice at the first contact; its cup path, tracked, scoops them again (docs/learners.md).
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>

namespace dicestack {

/// One recording, as the tracker uses it: the states before each action and the actions.
struct CupPath {
  std::string name;
  std::vector<State> states;
  std::vector<Action> actions;  ///< same length as states
};

/// How a recorded path is fitted to a start beyond the move into its frame: the spirit of the
/// paper's eq. 11, corrections that make a recording play back in this world.
struct PathWarp {
  double time_scale = 1.0;  ///< recorded steps per control step (> 1 plays it faster)
  double offset = 0.0;      ///< extra shift in x, m
  double amplitude = 1.0;   ///< the path's x about its dice' mean x is scaled by this
  double phase = 0.0;       ///< recorded steps already played at the follower's first step (a rescue joins midway)
};

/// Settings of the tracker. The warp bounds say how far a correction may go, they are not tuned
/// gains (docs/learners.md, "From recordings alone: the tracker").
struct TrackerConfig {
  double gain = 10.0;        ///< feedback gain on the cup's pose, 1/s (the issue's k)
  int probes = 16;           ///< training starts that rank the recordings (most successes first), >= 0
  int paths = 0;              ///< follow only the first `paths` recordings of the ranking (0: all), >= 0
  bool optimise = true;      ///< when no recording succeeds as recorded, search warps
  int optimise_paths = 4;    ///< the warp search tries the recordings that came closest, >= 1
  int optimise_evaluations = 60;   ///< simulated warps per recording (CMA-ES), >= 1
  double time_scale_range = 0.15;  ///< a search keeps |log time_scale| <= log(1 + this) about its base, in [0, 1)
  double offset_range = 0.3;       ///< |offset| <= this, m, per search (a rescue's join also moves x to meet the cup)
  double amplitude_range = 0.15;   ///< |amplitude - 1| <= this, in [0, 1), per search (a rescue's warps compose)
  int hold_steps = 60;       ///< a simulation ends this many steps after the path's end, >= 0
  /// Closed loop on the dice: every this many steps the rest of the followed path is simulated
  /// from the state reached; when it no longer ends in a success, a rescue joins a recording
  /// midway (rescue_path). 0: the path is chosen once per episode. >= 0.
  int rescue = 0;
  int rescue_evaluations = 30;  ///< simulated warps per recording in a rescue's search (CMA-ES), >= 1
  /// Each path's pose and velocity are smoothed by a Gaussian of this std, in steps, before it
  /// is followed (0: as recorded). A person's per-step jitter is no part of the motion a learner
  /// can fit: labels are the path's accelerations. In [0, 1000].
  double smooth = 0.0;
  /// Robust choices: a candidate that succeeds as simulated is also simulated this many times
  /// as a learner would play it (robust_trial: executed-action noise of std robust_noise x
  /// action.scale, and the whole path off by a random warp of std robust_warp), and the first
  /// whose trials all succeed is chosen; failing that, the success with most. The ranking's
  /// probes count those trials too. 0: off. In [0, 1000].
  int robust = 0;
  double robust_noise = 0.1;  ///< in [0, 10]
  double robust_warp = 0.0;   ///< std of each noisy trial's random warp (time scale, offset in m, amplitude), in [0, 1]
  /// A path moved to a start away from the recording's own swings that far nearer one wall: the
  /// recordings swing the cup ~3 m either side of the dice, up to the walls. With this, its swing
  /// is narrowed (about the dice) to reach no further than the recording's did.
  bool keep_extremes = false;
  /// When no recording succeeds as recorded, before CMA-ES: the swing narrowed about the dice in
  /// even steps (amplitude 1 - k amplitude_range / shrink, k = 1..shrink), the
  /// closest recordings at each step: the least change that succeeds, alike for neighbouring
  /// starts. 0: straight to CMA-ES. In [0, 100].
  int shrink = 0;
  /// Variants of the recordings: besides `smooth`, each of the `variant_recordings` best-ranked
  /// recordings is also ranked smoothed by each of these widths (steps, each in [0, 1000]); the
  /// `finalists` best-scoring paths are then scored again from `finalist_probes` further probe
  /// starts, and lead the order by their score over all their trials. Whether a path plays is a
  /// chaotic function of such details (one recording, smoothed by 1 step, plays from 59 of 100
  /// starts; by 4, from 27): the ranking picks the width. Empty: off.
  std::vector<double> variants;
  int variant_recordings = 8;  ///< >= 1
  int finalists = 4;           ///< >= 1
  int finalist_probes = 64;    ///< >= 0
  /// Paths robust by construction: the leading path's cup pose (and timing) is moved by smooth
  /// offsets (refine_knots bumps per axis over its length, each at most refine_range) that CMA-ES
  /// chooses, this many generations, to succeed from the most starts as followed, with and
  /// without executed-action noise of std refine_noise x action.scale. The refined path (the
  /// best of refine_restarts) leads the order when it beats the leading path from the same
  /// fresh starts. A recorded path's success is a lottery in details below what a person
  /// controls; a learner distilling the tracker succeeds about as often as its path does under
  /// its noise. 0: off. In [0, 10000].
  int refine = 0;
  int refine_probes = 32;  ///< starts per generation (each played clean and noisy), in [1, 100000]
  /// Refinements, each of the next path of the order (wrapping) from a seed of its own, until
  /// one succeeds in refine_enough of its validation trials; the one with most successes from
  /// the same fresh starts leads if it beats the leader. In [1, 100].
  int refine_restarts = 1;
  /// A refined path that succeeds in this share of its validation trials ends the restarts: a
  /// student distilling such a path stacks from nearly every start (paths at 216-237 of 256
  /// gave 97-100 %), and more refinements would cost minutes for nothing. In [0, 1].
  double refine_enough = 0.8;
  int refine_knots = 6;    ///< Gaussian bumps per axis, evenly spaced over the path, in [1, 100]
  /// Largest height of one bump per axis: x m, y m, angle rad, and timing s (0: the path keeps
  /// its timing). Neighbouring bumps overlap: together they move a step up to ~2.5 times this.
  std::array<double, 4> refine_range{0.2, 0.2, 0.2, 0.0};
  /// The noise of a refinement's noisy trials: DART's default with the tracker (0.1, 0.5, 0.2).
  Action refine_noise{0.1, 0.5, 0.2};
  /// What its simulations step on the arm: cup actions, or the same actions told in joint
  /// torques (told_in_torques), so that the path it chooses stacks under held torques. Not a
  /// setting by name: it follows the controller its expert answers (`--controller`).
  ActionKind controller = ActionKind::cup;
};

/// Throws ConfigError naming the first field of `config` out of its range.
void validate(const TrackerConfig& config);

/// The smoothing widths, in steps, that `variants=true` ranks each recording at.
inline constexpr std::array<double, 7> kTrackerVariantWidths{0.0, 1.0, 2.0, 3.0, 4.0, 6.0, 8.0};

/// Named tracker settings, as Hydra's config groups: a preset, then settings on top.
///  - "plain": TrackerConfig{}, the tracker as it follows recordings (record, robustness, Python);
///  - "distill": tuned for a learner distilling it (the learners' default): the 3 best-ranked
///    recordings, smoothed by 4 steps, chosen robust to a learner's errors (5 noisy trials,
///    warps of std 0.02), narrowed in 5 steps before warped, each recording's smoothing chosen
///    among kTrackerVariantWidths, up to the 4 leading paths refined for 60 generations each
///    (refine, refine_restarts) until one passes refine_enough, the best by validation leading. Measured
///    in docs/notebook/2026-11-27-learners-page-history.md ("Policies from the human recordings")
///    and docs/notebook/2026-11-28-refined-paths.md; the recipe: docs/learners.md.
/// Throws ConfigError for another name, listing the presets.
TrackerConfig tracker_preset(std::string_view name);
/// The presets' names, in listing order.
std::vector<std::string> tracker_preset_names();

/// The settings a user may give by name ("NAME=VALUE"), each a TrackerConfig field: probes,
/// optimise, paths, smooth, rescue, robust, robust_noise, robust_warp, keep_extremes, shrink,
/// variants (true: kTrackerVariantWidths, false: none), refine, refine_probes, refine_restarts and
/// refine_timing (refine_range's timing axis). `probes` also sets finalist_probes to 4
/// times it (finalists are scored from four times the ranking's starts).
std::vector<std::string> tracker_setting_names();
/// Sets one of them from text. Throws ConfigError naming the setting and what it takes.
void set_tracker_setting(TrackerConfig& config, std::string_view name, std::string_view value);
/// A tracker told in joint torques, with the settings not given (`given` says by name) made what
/// held torques need: no refinement (a generation in held torques takes about 10 s on 2 cores),
/// and at least 32 probe starts to rank the path it then follows unrefined (16 ranked a weaker
/// one first for one learner's seed in three). Sets `controller`.
void settle_for_joint_torques(TrackerConfig& config, const std::function<bool(std::string_view)>& given);
/// The value of one of them in `config`, as text set_tracker_setting reads back the same.
std::string tracker_setting_text(const TrackerConfig& config, std::string_view name);
/// Every setting of `config`, "NAME=VALUE, ...", in tracker_setting_names' order: what a
/// model records of the tracker that taught it.
std::string tracker_summary(const TrackerConfig& config);
/// tracker_preset(preset) with each "NAME=VALUE" of `settings` on top, validated.
TrackerConfig tracker_config(std::string_view preset, const std::vector<std::string>& settings);

/// Follows one recorded path moved into a start's frame (x shifted by the difference of the
/// dice' mean x in `start` and in the recording's first state), then warped: dv = v_ref +
/// gain (p_ref - p) - v on the cup's x, y and angle, with v_ref the recorded velocity after the
/// recorded action. After the path's end it holds the
/// last pose. act() is a pure function of the state and the step.
class PathFollower {
 public:
  PathFollower() = default;
  /// `path` must outlive the follower.
  /// keep_extremes: narrow the swing (amplitude about the dice) so that the moved path reaches
  /// no further left or right than the recording did (TrackerConfig::keep_extremes).
  PathFollower(const CupPath& path, const PathWarp& warp, const State& start, int start_step, double gain,
               bool keep_extremes = false);

  Action act(const State& s, int step) const;
  /// Control steps from the start step to the path's end.
  int length() const { return length_; }
  /// Recorded steps played by control step `step`.
  double phase(int step) const;
  bool valid() const { return path_ != nullptr; }

 private:
  const CupPath* path_ = nullptr;
  PathWarp warp_;
  int start_step_ = 0, length_ = 0;  // length_: steps from start_step_ to the path's end
  double centre_ = 0.0, shift_ = 0.0, gain_ = 10.0;
};

/// How far the preparation of Recordings has come, for a progress display: `stage` ("ranking the
/// paths", "refining path 2 of 4") and `done` of `total` work items in it (a refinement's
/// generations). Called on the constructing thread, between steps of the work.
using TrackerProgress = std::function<void(const std::string& stage, int done, int total)>;

/// Recordings prepared for the tracker: each path (with TrackerConfig::variants, the
/// recordings' variants after them, named "NAME (smoothed W)"), and their order of trial. Built
/// once (the ranking simulates every path from `config.probes` training starts) and shared,
/// read-only, by every tracker expert on every thread. The order is a deterministic function of the paths,
/// the world, the config and the seed: the same on any number of threads or ranks.
class Recordings {
 public:
  /// Throws InputError if `paths` is empty, or a path is empty, has states and actions of
  /// different lengths or a value that is not finite (naming the path and step); ConfigError
  /// for a bad config. Collective over `cluster`: the probe simulations are dealt among its ranks.
  Recordings(std::vector<CupPath> paths, const WorldConfig& world, const TrackerConfig& config, std::uint64_t seed,
             int threads = 0, Cluster& cluster = local_cluster(), const TrackerProgress& progress = {});

  const std::vector<CupPath>& paths() const { return paths_; }
  /// Path indices in the order the tracker tries them: highest probe score first, then by index;
  /// only the first config.paths of them when paths > 0 (the others are never followed).
  const std::vector<std::size_t>& order() const { return order_; }
  /// Probe score per path (index as in paths()): its successes from the probe starts, and with
  /// robust, 1 more for each noisy trial of such a success that also succeeds. A refined path's
  /// is its successes in its validation trials.
  const std::vector<int>& probe_successes() const { return probe_successes_; }
  /// The trials each probe score counts: probes x (1 + robust), more for a finalist; a refined
  /// path's, its validation trials (8 x refine_probes).
  const std::vector<int>& probe_trials() const { return probe_trials_; }
  const TrackerConfig& config() const { return config_; }
  std::uint64_t seed() const { return seed_; }

 private:
  /// The first `count` paths by probe score, most successes first, then by index.
  std::vector<std::size_t> ranked(std::size_t count) const;
  /// Refines the paths that lead the order (TrackerConfig::refine, refine_restarts), adds them
  /// to paths() with their validation successes as their probe scores, and puts the best first
  /// if it beats the leader there; the others go last.
  void refine_leaders(const WorldConfig& world, int threads, Cluster& cluster, const TrackerProgress& progress);
  /// Probe scores of paths [from, to) from probe starts [first_probe, first_probe + probes).
  std::vector<int> probe_scores(const WorldConfig& world, int threads, Cluster& cluster, std::size_t from, std::size_t to,
                                int first_probe, int probes, bool variants) const;

  std::vector<CupPath> paths_;
  TrackerConfig config_;
  std::uint64_t seed_ = 0;
  std::vector<std::size_t> order_;
  std::vector<int> probe_successes_, probe_trials_;
};

/// What the tracker's search chose for one start.
struct TrackerChoice {
  std::size_t path = 0;  ///< index into Recordings::paths()
  PathWarp warp;
  bool success = false;  ///< its simulated episode ended in a realistic success
  int simulations = 0;   ///< episodes simulated to choose it
};

/// Searches `recordings` from env's current state, simulating in `sim` (an environment of the
/// same world): the first path in order() whose simulated episode is a realistic success (with
/// robust: whose noisy trials succeed too, else the success with most); if none and
/// config.optimise, the paths that came closest narrowed (shrink), then warped (CMA-ES,
/// seeded by `seed`); failing all, the closest (fewest judge tolerances from a stack, no wall).
/// Deterministic in the state, the recordings and `seed`.
TrackerChoice choose_path(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, std::uint64_t seed);

/// Whether `follower`, followed from env's current state, simulates to a realistic success
/// within `follower.length() + hold_steps` steps from now (and the episode's limit). For a
/// follower started earlier that is longer than the rest of its path plus the hold: a lenient
/// check, as measured (docs/notebook/2026-11-27-learners-page-history.md, "A demonstrator that
/// chooses again: rescue and smoothing").
bool still_succeeds(const PathFollower& follower, const DiceEnv& env, DiceEnv& sim, int hold_steps, ActionKind controller);

/// A cup action told in joint torques in `env` (an arm's): it runs through the cup controller
/// from env's state; the torques that step held on average (World::arm_step_torques), corrected
/// once by the chain's dynamics towards the cup velocity the step ended at (arm_torque_change),
/// are the answer. `env` is put back exactly where it was. Throws InputError for a floating cup.
Action told_in_torques(DiceEnv& env, const Action& cup);

/// The cup action that takes a floating cup from `before` to `after`'s velocity one control step
/// later in `world`: its velocity change before gravity's pull over the step. Exact in free
/// flight; in contact it also holds what the contacts did. What a step recorded in joint torques
/// reads as a cup action, for the feedback law that follows the velocity during each step.
Action cup_action_between(const State& before, const State& after, const WorldConfig& world);

/// A rescue, mid-episode, when the followed path (`current`, moved into the frame of `frame`,
/// the episode's start) no longer simulates to a success from env's state: its rest, then every
/// recording joined at its step nearest the state (the cup's pose and velocity, the dice
/// relative to the cup) with x moved to meet the cup, first success wins; if none and
/// config.optimise, warps of the closest. Failing all, the closest, which may be `current`.
/// Deterministic in the state, `current`, the recordings and `seed`.
TrackerChoice rescue_path(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, const State& frame,
                          const TrackerChoice& current, double current_phase, std::uint64_t seed);

}  // namespace dicestack
