#pragma once
// The outcome judge (DESIGN "Outcome judge", paper III-B/C): how many dice the cup holds,
// whether the dice stand stacked, and whether anything touched a wall.
#include <cstddef>
#include <span>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// Dice whose centre lies inside the cup (between its walls, between base and rim) while the
/// die is off the table (centre 2 x judge.gap_tolerance above a resting die's), whatever the cup's angle: the human technique swings the cup
/// mouth-down and holds the dice against its base by centripetal acceleration. Dice lying on
/// the table under the cup do not count.
int count_dice_in_cup(const State& state, const WorldConfig& config);

/// True when the three dice form one vertical column at rest on the table: in any order, at
/// any x, each rotated by a multiple of 90 degrees (within config.judge's tolerances). Dice
/// side by side, a leaning or offset column, or a moving one are not stacked.
bool is_stacked(const State& state, const WorldConfig& config);

/// How far `state` is from is_stacked: the sum over is_stacked's tests of each deviation in
/// units of its tolerance (a state is stacked when every term is at most 1). For searches that
/// must rank near misses (the tracker's choice) without a cost of their own.
double stack_shortfall(const State& state, const WorldConfig& config);

/// A failed attempt, come to rest: every die at rest (judge.rest_speed and rest_angular_speed),
/// the lowest on the table (not held in the air by a cup kept still), and the dice not
/// stacked. Nothing more happens to them unless the cup scoops them again.
bool failed_at_rest(const State& state, const WorldConfig& config);

/// When an episode's attempts begin: at step 0, and again at the first step, from `earliest`
/// on, that ends `rest_steps` states in a row failed_at_rest (the dice are left as a failed
/// attempt left them, and a new attempt may scoop them again). A function of the states alone,
/// so that a demonstrator that tries again and a feature map that restarts its clock there
/// agree on every step.
struct AttemptRule {
  int earliest = 60;    ///< no attempt begins before this step (the dice rest before the first scoop)
  int rest_steps = 10;  ///< failed_at_rest for this many states in a row
};

/// The step the attempt in progress at the last of `states` (states[0] the start, one per step)
/// began at, under `rule`, judged with `config`. 0 for an empty span.
std::size_t attempt_start(std::span<const State> states, const WorldConfig& config, const AttemptRule& rule = {});

/// What happened in an episode so far.
struct Outcome {
  int steps = 0;             ///< control steps taken
  int dice_in_cup = 0;       ///< most dice held in the cup at once during the episode (0-3)
  int dice_in_cup_now = 0;   ///< dice in the cup in the latest state
  bool stacked = false;      ///< the latest state is stacked
  bool wall_contact = false; ///< the cup or a die touched a side wall or the ceiling at any time
  int stacked_steps = 0;     ///< consecutive steps the dice have been stacked, up to the latest
  /// Stacked without ever touching a wall: the paper's realistic success (III-C).
  bool realistic_success() const { return stacked && !wall_contact; }
};

/// What happens when a recording ends while a finished stack still wobbles: from `state`, the
/// cup is held still (its velocity cancelled every step) for up to `max_steps` control steps.
struct Settled {
  bool stacked = false;       ///< the dice came to rest stacked
  bool wall_contact = false;  ///< something touched a side wall or the ceiling meanwhile
  int steps = 0;              ///< steps simulated
};
Settled settle(const State& state, const WorldConfig& config, int max_steps = 60);

/// Updates an Outcome with one more state; `wall_contact_step` is what World::step returned.
void observe(Outcome& outcome, const State& state, bool wall_contact_step, const WorldConfig& config);

}  // namespace dicestack
