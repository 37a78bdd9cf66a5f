// Evaluation: Wilson intervals, rates and per-rollout results that agree with stepping the world
// by hand on any thread count, and playback of a recorded rollout.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

// A deterministic controller with per-episode state, for testing the evaluation machinery.
class Swing final : public Policy {
 public:
  void reset(std::uint64_t seed) override { phase_ = static_cast<int>(seed % 7); }
  Action act(const History& h) override {
    const State& s = h.current();
    ++phase_;
    return {(phase_ / 10) % 2 ? 0.4 : -0.4, 4.0 / 30.0 - s[state_index::kCupVy] * 0.5, -0.1 * s[state_index::kCupW]};
  }
  std::string name() const override { return "swing"; }

 private:
  int phase_ = 0;
};

TEST(Evaluate, WilsonIntervalsMatchKnownValues) {
  const Rate r = wilson(8, 10);
  EXPECT_NEAR(r.value, 0.8, 1e-12);
  EXPECT_NEAR(r.low, 0.4902, 1e-3);
  EXPECT_NEAR(r.high, 0.9433, 1e-3);
  const Rate zero = wilson(0, 20);
  EXPECT_EQ(zero.low, 0.0);
  EXPECT_NEAR(zero.high, 0.1611, 1e-3);
}

TEST(Evaluate, ResultsDoNotDependOnThreadCount) {
  WorldConfig c;
  c.episode.max_steps = 60;
  std::vector<Episode> one, two;
  const auto make = [] { return std::make_unique<Swing>(); };
  const EvalStats a = evaluate(make, c, test::eval_request(6, 3, 1, &one));
  const EvalStats b = evaluate(make, c, test::eval_request(6, 3, 2, &two));
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states) << "episode " << i;
    EXPECT_EQ(one[i].actions, two[i].actions);
  }
  EXPECT_EQ(a.wall_contact.value, b.wall_contact.value);
  EXPECT_EQ(a.dice_in_cup_mean, b.dice_in_cup_mean);
}

TEST(Evaluate, RatesAgreeWithRollingOutByHand) {
  WorldConfig c;
  c.episode.max_steps = 80;
  std::vector<Episode> eps;
  const EvalStats s = evaluate([] { return std::make_unique<Swing>(); }, c, test::eval_request(5, 9, 2, &eps, InitialPush::left));
  int walls = 0;
  double cup = 0.0;
  DiceEnv env(c);
  for (std::size_t i = 0; i < 5; ++i) {
    Swing p;
    const std::uint64_t seed = derive_seed(9, i);
    RolloutOptions left;
    left.push = InitialPush::left;
    const Episode e = rollout(env, p, random_start_state(c, seed), seed, StepSource::policy, left);
    EXPECT_EQ(e.states, eps[i].states);
    walls += e.outcome.wall_contact;
    cup += e.outcome.dice_in_cup;
    EXPECT_NEAR(e.actions[0][0], -0.4 - 1.0, 1e-12) << "the left push adds -1 m/s at the first step";
  }
  EXPECT_EQ(s.wall_contact.value, walls / 5.0);
  EXPECT_EQ(s.dice_in_cup_mean, cup / 5.0);
  EXPECT_EQ(s.mean_length, 80.0);
}

// Each rollout's results, the first wall contact's step included, as stepping the world by hand
// finds them (the left push makes walls likely; some rollouts must touch one for the test to bite).
TEST(Evaluate, PerRolloutResultsAgreeWithSteppingByHand) {
  WorldConfig c;
  c.episode.max_steps = 80;
  std::vector<EpisodeResult> results;
  EvalRequest request = test::eval_request(6, 9, 2, nullptr, InitialPush::left);
  request.results = &results;
  evaluate([] { return std::make_unique<Swing>(); }, c, request);
  ASSERT_EQ(results.size(), 6u);
  DiceEnv env(c);
  int touched = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const std::uint64_t seed = derive_seed(9, i);
    Swing p;
    p.reset(seed);
    std::vector<State> states{env.reset_to(random_start_state(c, seed), seed)};
    std::vector<Action> applied;
    int wall_step = -1;
    double reward = 0.0;
    StepResult r;
    do {
      Action a = p.act(History{states, applied});
      if (applied.empty()) a[0] -= 1.0;
      r = env.step(a);
      if (wall_step < 0 && r.info.outcome.wall_contact) wall_step = static_cast<int>(applied.size());
      applied.push_back(r.applied);
      reward += r.reward;
      states.push_back(r.observation);
    } while (!r.terminated && !r.truncated);
    EXPECT_EQ(results[i].index, static_cast<int>(i));
    EXPECT_EQ(results[i].seed, seed);
    EXPECT_EQ(results[i].wall_step, wall_step) << "rollout " << i;
    EXPECT_EQ(results[i].wall_contact, wall_step >= 0);
    EXPECT_EQ(results[i].length, static_cast<int>(applied.size()));
    EXPECT_DOUBLE_EQ(results[i].reward, reward);
    EXPECT_EQ(results[i].success, r.info.outcome.realistic_success());
    touched += wall_step >= 0 && wall_step < results[i].length - 1;
  }
  EXPECT_GT(touched, 0) << "no rollout touched a wall before its last step";
}

TEST(Evaluate, PlaybackReplaysARecordedRolloutExactly) {
  WorldConfig c;
  c.episode.max_steps = 50;
  DiceEnv env(c);
  Swing p;
  const Episode demo = rollout(env, p, random_start_state(c, 4), 4, StepSource::expert);
  PlaybackPolicy playback(demo);
  const Episode again = rollout(env, playback, demo.states.front(), 4, StepSource::policy);
  EXPECT_EQ(again.states, demo.states);
  EXPECT_EQ(again.outcome.wall_contact, demo.outcome.wall_contact);
}

}  // namespace
}  // namespace dicestack
