// PerturbedEnv: one episode's world, what its policy is shown and what runs, in one place.
#include <gtest/gtest.h>

#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/perturbed_env.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

TEST(PerturbedEnv, RunsInThePooledWorldUnlessTheDrawChangesThePhysics) {
  const WorldConfig w;
  DiceEnv pooled(w);
  PerturbedEnv nominal(pooled, Perturbation{}, 3);
  EXPECT_EQ(&nominal.env(), &pooled);
  EXPECT_FALSE(nominal.perturbed());
  EXPECT_FALSE(nominal.channelled());
  EXPECT_TRUE(nominal.pending().empty());
  EXPECT_TRUE(test::bit_equal(nominal.random_start(3), random_start_state(w, 3)));

  PerturbedEnv heavy(pooled, perturbation_factor("dice_mass", "hard"), 3);
  EXPECT_NE(&heavy.env(), &pooled);
  EXPECT_TRUE(heavy.perturbed());
  EXPECT_EQ(heavy.env().config(), heavy.draw().world);
  EXPECT_FALSE(heavy.env().config() == w);
}

TEST(PerturbedEnv, ResetStartsAsTheDrawnWorldsOwnResetDoes) {
  const WorldConfig w;
  DiceEnv pooled(w);
  PerturbedEnv heavy(pooled, perturbation_factor("dice_mass", "hard"), 5);
  DiceEnv own(heavy.draw().world);
  EXPECT_TRUE(test::bit_equal(heavy.reset(5), own.reset(5)));
  EXPECT_TRUE(test::bit_equal(heavy.step({1.0, 0.5, 0.0}).result.observation, own.step({1.0, 0.5, 0.0}).observation));
}

TEST(PerturbedEnv, ClipsWhatThePolicyChoseThenDelaysItAndShowsTheStateLate) {
  const WorldConfig w;
  DiceEnv pooled(w), plain(w);
  PerturbationDraw d = draw_perturbation(Perturbation{}, w, 1);
  d.acts = true;
  d.action_delay = 1;
  d.observation_delay = 1;
  PerturbedEnv late(pooled, d);
  ASSERT_TRUE(late.channelled());
  const State start = random_start_state(w, 1);
  const State at_start = late.reset_to(start, 1);  // the world's own (floats) start
  EXPECT_TRUE(test::bit_equal(at_start, late.env().get_state()));
  plain.reset_to(start, 1);
  const Action far{1e6, -1e6, 0.0};
  EXPECT_EQ(late.clip(far), (Action{w.action.limit[0], -w.action.limit[1], 0.0}));
  // The first step runs nothing (the delay); the clipped choice is pending and shows next.
  const PerturbedStep first = late.step(far);
  const StepResult idle = plain.step({0.0, 0.0, 0.0});
  EXPECT_TRUE(test::bit_equal(first.result.observation, idle.observation));
  EXPECT_TRUE(test::bit_equal(first.shown, at_start));  // a step late
  ASSERT_EQ(late.pending().size(), 1u);
  EXPECT_EQ(late.pending().front(), late.clip(far));
  const PerturbedStep second = late.step({0.0, 0.0, 0.0});
  const StepResult moved = plain.step(late.clip(far));
  EXPECT_TRUE(test::bit_equal(second.result.observation, moved.observation));
  EXPECT_TRUE(test::bit_equal(second.shown, first.result.observation));
}

TEST(PerturbedEnv, ExecutedNoiseMovesTheWorldFromItsOwnStream) {
  const WorldConfig w;
  DiceEnv a(w), b(w), c(w);
  PerturbedEnv noisy(a), same(b), other(c);
  noisy.add_executed_noise({0.1, 0.1, 0.1}, 7);
  same.add_executed_noise({0.1, 0.1, 0.1}, 7);
  other.add_executed_noise({0.1, 0.1, 0.1}, 8);
  const State start = random_start_state(w, 2);
  for (PerturbedEnv* e : {&noisy, &same, &other}) e->reset_to(start, 2);
  State x{}, y{}, z{};
  for (int t = 0; t < 5; ++t) {
    x = noisy.step({0.0, 0.0, 0.0}).result.observation;
    y = same.step({0.0, 0.0, 0.0}).result.observation;
    z = other.step({0.0, 0.0, 0.0}).result.observation;
  }
  EXPECT_TRUE(test::bit_equal(x, y));
  EXPECT_FALSE(test::bit_equal(x, z));
  EXPECT_FALSE(test::bit_equal(x, start));
}

}  // namespace
}  // namespace dicestack
