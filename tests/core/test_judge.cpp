#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <span>
#include <vector>

#include <dicestack/core/judge.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
constexpr double kPi = std::numbers::pi;

// A state with the cup upright at rest far to the right and the dice in a column at x, in
// the given order (bottom first) and quarter turns.
State column(double x, std::array<std::size_t, 3> order = {0, 1, 2}, std::array<int, 3> turns = {0, 0, 0}) {
  State s{};
  s[si::kCupX] = 7.5;
  s[si::kCupY] = 1.0 + 0.05 + 2.2 / 3.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t d = si::die(order[k]);
    s[d] = x;
    s[d + 1] = 1.2 + 0.4 * static_cast<double>(k);
    s[d + 2] = turns[k] * kPi / 2.0;
  }
  return s;
}

TEST(Judge, ColumnIsStackedAtAnyXOrderAndQuarterTurn) {
  const WorldConfig c;
  EXPECT_TRUE(is_stacked(column(4.51), c));
  EXPECT_TRUE(is_stacked(column(2.0), c));
  EXPECT_TRUE(is_stacked(column(6.3, {2, 0, 1}), c));
  EXPECT_TRUE(is_stacked(column(3.0, {1, 2, 0}, {1, -2, 7}), c));
  State s = column(4.0);
  s[si::die(1)] += 0.09;  // offset like the paper's imitate_2 stack, within tolerance
  s[si::die(2) + 2] += 0.05;
  EXPECT_TRUE(is_stacked(s, c));
}

TEST(Judge, SideBySideLeaningMovingOrFloatingIsNotStacked) {
  const WorldConfig c;
  State side = column(4.0);
  for (std::size_t i = 0; i < 3; ++i) {
    side[si::die(i)] = 3.0 + 0.45 * static_cast<double>(i);
    side[si::die(i) + 1] = 1.2;
  }
  EXPECT_FALSE(is_stacked(side, c));

  State leaning = column(4.0);
  leaning[si::die(1)] += 0.12;
  leaning[si::die(2)] += 0.24;
  EXPECT_FALSE(is_stacked(leaning, c));

  State tilted = column(4.0);
  tilted[si::die(2) + 2] = 0.4;
  EXPECT_FALSE(is_stacked(tilted, c));

  State moving = column(4.0);
  moving[si::die(2) + 3] = 0.3;
  EXPECT_FALSE(is_stacked(moving, c));
  State spinning = column(4.0);
  spinning[si::die(0) + 5] = 1.0;
  EXPECT_FALSE(is_stacked(spinning, c));

  State floating = column(4.0);
  for (std::size_t i = 0; i < 3; ++i) floating[si::die(i) + 1] += 0.5;
  EXPECT_FALSE(is_stacked(floating, c));

  State two_high = column(4.0);
  two_high[si::die(2)] = 6.0;
  two_high[si::die(2) + 1] = 1.2;
  EXPECT_FALSE(is_stacked(two_high, c));
}

TEST(Judge, DiceInCupCountsOnlyHeldDice) {
  const WorldConfig c;
  State s = column(2.0);
  // Cup upright in the air at x = 5, dice 0 and 1 inside above its base, die 2 on the table.
  s[si::kCupX] = 5.0;
  s[si::kCupY] = 3.0;
  s[si::kCupAngle] = 0.1;
  s[si::die(0)] = 5.0;
  s[si::die(0) + 1] = 3.0 - 2.2 / 3.0 + 0.3;
  s[si::die(1)] = 5.1;
  s[si::die(1) + 1] = 3.0;
  EXPECT_EQ(count_dice_in_cup(s, c), 2);
  // Mouth down, swinging: the dice pressed against the base (now above them) still count.
  State flipped = s;
  flipped[si::kCupAngle] = kPi;
  flipped[si::die(0) + 1] = 3.0 + 2.2 / 3.0 - 0.3;
  flipped[si::die(1) + 1] = 3.0;
  flipped[si::die(1)] = 4.9;
  EXPECT_EQ(count_dice_in_cup(flipped, c), 2);
  // Dice lying on the table under the mouth-down cup at the start are not held.
  State start = column(4.0);
  for (std::size_t i = 0; i < 3; ++i) {
    start[si::die(i)] = 4.1 + 0.4 * static_cast<double>(i);
    start[si::die(i) + 1] = 1.2;
  }
  start[si::kCupX] = 4.5;
  start[si::kCupY] = 2.5;
  start[si::kCupAngle] = kPi;
  EXPECT_EQ(count_dice_in_cup(start, c), 0);
  EXPECT_EQ(count_dice_in_cup(column(4.0), c), 0);
}

// Three dice side by side on the table at rest, the cup up and away: a failed attempt at rest.
State side_by_side() {
  State s = column(4.0);
  for (std::size_t i = 0; i < 3; ++i) {
    s[si::die(i)] = 3.0 + 0.45 * static_cast<double>(i);
    s[si::die(i) + 1] = 1.2;
  }
  return s;
}

TEST(Judge, AFailedAttemptAtRestIsDiceStillUnstackedAndDown) {
  const WorldConfig c;
  EXPECT_TRUE(failed_at_rest(side_by_side(), c));
  EXPECT_FALSE(failed_at_rest(column(4.0), c)) << "stacked is a success, not a failure";
  State moving = side_by_side();
  moving[si::die(1) + 3] = 0.3;
  EXPECT_FALSE(failed_at_rest(moving, c));
  State spinning = side_by_side();
  spinning[si::die(2) + 5] = 1.0;
  EXPECT_FALSE(failed_at_rest(spinning, c));
  State held = side_by_side();  // the dice at rest in a cup kept still in the air
  held[si::kCupX] = 5.0;
  held[si::kCupY] = 3.0;
  for (std::size_t i = 0; i < 3; ++i) {
    held[si::die(i)] = 4.8 + 0.2 * static_cast<double>(i);
    held[si::die(i) + 1] = 3.0 - 2.2 / 3.0 + 0.3;
  }
  ASSERT_EQ(count_dice_in_cup(held, c), 3);
  EXPECT_FALSE(failed_at_rest(held, c)) << "dice not down yet";
  State covered = column(4.0);  // a column fallen over to one side, the cup left over it
  covered[si::die(2)] += 0.3;
  covered[si::kCupX] = 4.0;
  covered[si::kCupY] = 2.6;
  covered[si::kCupAngle] = kPi;
  ASSERT_GT(count_dice_in_cup(covered, c), 0);
  EXPECT_TRUE(failed_at_rest(covered, c)) << "a cup left still over the dice";
}

TEST(Judge, AnAttemptBeginsWhereAFailureHasRestedLongEnoughAndNotBeforeTheEarliestStep) {
  const WorldConfig c;
  const AttemptRule rule;  // earliest 60, rest_steps 10
  State moving = side_by_side();
  moving[si::die(0) + 3] = 0.5;
  auto episode = [&](std::initializer_list<std::pair<int, bool>> runs) {  // (steps, at rest)
    std::vector<State> states;
    for (const auto& [n, rest] : runs) states.insert(states.end(), static_cast<std::size_t>(n), rest ? side_by_side() : moving);
    return states;
  };
  auto start = [&](const std::vector<State>& states, std::size_t upto) {
    return attempt_start(std::span<const State>(states.data(), upto + 1), c, rule);
  };
  EXPECT_EQ(attempt_start({}, c, rule), 0u);
  // The dice rest before the first scoop: that run starts nothing before step 60 ...
  const auto waits = episode({{30, true}, {40, false}, {30, true}});
  for (std::size_t t = 0; t < 79; ++t) EXPECT_EQ(start(waits, t), 0u) << t;
  // ... a failure resting 10 states (70 .. 79) starts an attempt at 79, and it stays the start.
  for (std::size_t t = 79; t < waits.size(); ++t) EXPECT_EQ(start(waits, t), 79u) << t;
  // A cup that never moves: the start's own rest starts an attempt at the earliest step.
  const auto idle = episode({{100, true}});
  EXPECT_EQ(start(idle, 59), 0u);
  EXPECT_EQ(start(idle, 99), 60u);
  // Too short a rest starts nothing; of two failures, the later one's attempt is in progress.
  const auto twice = episode({{20, false}, {50, false}, {5, true}, {20, false}, {12, true}, {80, false}, {15, true}});
  EXPECT_EQ(start(twice, 103), 0u);
  EXPECT_EQ(start(twice, 104), 104u);  // the rest from 95: 10 states by 104
  EXPECT_EQ(start(twice, 195), 104u);
  EXPECT_EQ(start(twice, 196), 196u);
  EXPECT_EQ(start(twice, 201), 196u);
  // A column at rest is a success, whatever its length: no attempt after it.
  std::vector<State> stacked(100, column(4.0));
  EXPECT_EQ(attempt_start(stacked, c, rule), 0u);
}

TEST(Judge, OutcomeTracksMaximaAndWallContact) {
  const WorldConfig c;
  Outcome o;
  observe(o, column(4.0), false, c);
  EXPECT_TRUE(o.realistic_success());
  EXPECT_EQ(o.stacked_steps, 1);
  observe(o, column(4.0), true, c);
  EXPECT_TRUE(o.stacked);
  EXPECT_TRUE(o.wall_contact);
  EXPECT_FALSE(o.realistic_success());
  State side = column(4.0);
  side[si::die(2)] = 6.0;
  observe(o, side, false, c);
  EXPECT_EQ(o.stacked_steps, 0);
  EXPECT_TRUE(o.wall_contact) << "wall contact is sticky for the episode";
  EXPECT_EQ(o.steps, 3);
}

}  // namespace
}  // namespace dicestack
