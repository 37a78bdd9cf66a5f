#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/rng.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using test::bit_equal;

ExpertEpisode run_from(const std::string& name, const State& start, std::uint64_t seed, bool keep = false) {
  const WorldConfig c;
  DiceEnv env(c);
  env.reset_to(start, seed);
  auto expert = make_expert(name);
  expert->reset(seed);
  return run_expert_episode(*expert, env, keep);
}

TEST(Expert, BothExpertsStackFromThePaperStartWithoutTouchingAWall) {
  for (const std::string name : {"scripted", "mpc"}) {
    const ExpertEpisode e = run_from(name, paper_start_state(WorldConfig{}), 0);
    EXPECT_TRUE(e.outcome.realistic_success()) << name;
    EXPECT_FALSE(e.outcome.wall_contact) << name;
    EXPECT_LT(e.outcome.steps, WorldConfig{}.episode.max_steps) << name;
  }
}

// The actions mpc chooses while someone else's (noisy) actions move the world.
std::vector<Action> mpc_labels_under_noise(const ExpertConfig& config) {
  WorldConfig w;
  w.episode.max_steps = 120;
  DiceEnv env(w);
  auto expert = make_expert("mpc", config);
  env.reset_to(random_start_state(w, 21), 21);
  expert->reset(21);
  Rng noise(5);
  std::vector<Action> labels;
  for (int t = 0; t < 120; ++t) {
    Action a = expert->act(env);
    labels.push_back(a);
    for (std::size_t k = 0; k < kActionDim; ++k) a[k] += 0.1 * w.action.scale[k] * noise.normal();
    env.step(a);
  }
  return labels;
}

TEST(Expert, MpcWithoutReplanningKeepsTheFirstPlan) {
  ExpertConfig once;
  once.replan = false;
  ExpertConfig never_due;  // the same by another road: a replanning interval no episode reaches
  never_due.replan_interval = 1 << 30;
  const auto a = mpc_labels_under_noise(once);
  EXPECT_EQ(a, mpc_labels_under_noise(never_due));
  EXPECT_NE(a, mpc_labels_under_noise(ExpertConfig{}));  // replanning under noise answers otherwise
}

// Plan-once mpc from random start 3, knocked at step 60 (dvx -0.6).
test::KnockedEpisode knocked_mpc(bool retry) {
  const WorldConfig w;
  ExpertConfig c;
  c.replan = false;
  c.retry = retry;
  auto expert = make_expert("mpc", c);
  DiceEnv env(w);
  env.reset_to(random_start_state(w, 3), 3);
  expert->reset(3);
  return test::knocked_episode(*expert, env, 60, {-0.6, 0.0, 0.0});
}

TEST(Expert, MpcTriesAgainWithANewPlanWhereAFailedAttemptCameToRestWhenAskedTo) {
  // Choosing its plan once, mpc follows it through the knock to a failure whose dice come to
  // rest; with retry it searches a new plan there (attempt_start) and stacks, acting as before
  // until then, the same way twice.
  const WorldConfig w;
  const test::KnockedEpisode once = knocked_mpc(false);
  const std::size_t restart = attempt_start(once.states, w);
  EXPECT_FALSE(once.success);
  ASSERT_GT(restart, 60u) << "the failure comes to rest";
  const test::KnockedEpisode again = knocked_mpc(true);
  EXPECT_TRUE(again.success);
  EXPECT_EQ(attempt_start(again.states, w), restart);
  ASSERT_GT(again.actions.size(), restart);
  for (std::size_t t = 0; t < restart; ++t) EXPECT_EQ(again.actions[t], once.actions[t]) << t;
  EXPECT_NE(again.actions[restart], once.actions[restart]) << "a new plan at the restart";
  EXPECT_EQ(knocked_mpc(true).actions, again.actions);
}

TEST(Expert, MpcRobustTrialsWithoutNoiseKeepThePlanAndWithNoiseAreSeeded) {
  ExpertConfig once;
  once.replan = false;
  const auto plain = mpc_labels_under_noise(once);
  ExpertConfig noiseless = once;  // trials that replay the plan exactly all succeed: the same plan
  noiseless.robust_trials = 3;
  noiseless.robust_noise = 0.0;
  EXPECT_EQ(mpc_labels_under_noise(noiseless), plain);
  ExpertConfig robust = once;
  robust.robust_trials = 3;
  EXPECT_EQ(mpc_labels_under_noise(robust), mpc_labels_under_noise(robust));  // the trials' noise is seeded
  robust.robust_trials = -1;
  EXPECT_THAT(test::error_of([&] { make_expert("mpc", robust); }), testing::HasSubstr("robust_trials"));
}

TEST(Expert, MpcStacksFromRandomStarts) {
  const WorldConfig c;
  int successes = 0;
  for (std::uint64_t seed = 0; seed < 4; ++seed) {
    DiceEnv env(c);
    env.reset(seed);
    auto expert = make_expert("mpc");
    expert->reset(seed);
    successes += run_expert_episode(*expert, env).outcome.realistic_success();
  }
  EXPECT_GE(successes, 3);
}

TEST(Expert, ActionsAreFiniteAndWithinTheLimits) {
  const WorldConfig c;
  const ExpertEpisode e = run_from("scripted", random_start_state(c, 5), 5, true);
  ASSERT_EQ(e.actions.size(), e.states.size());
  ASSERT_FALSE(e.actions.empty());
  for (const Action& a : e.actions)
    for (std::size_t k = 0; k < kActionDim; ++k) {
      EXPECT_TRUE(std::isfinite(a[k]));
      EXPECT_LE(std::abs(a[k]), c.action.limit[k]);
    }
}

TEST(Expert, TheHumanStrategy_CupStaysMouthDownAndSwingsBothWays) {
  // The recordings keep the cup mouth-down and swing it left and right (docs/expert.md).
  const ExpertEpisode e = run_from("scripted", paper_start_state(WorldConfig{}), 0, true);
  double min_x = 1e9, max_x = -1e9;
  for (const State& s : e.states) {
    EXPECT_LT(std::cos(s[si::kCupAngle]), 0.0);
    min_x = std::min(min_x, s[si::kCupX]);
    max_x = std::max(max_x, s[si::kCupX]);
  }
  EXPECT_GT(max_x - min_x, 2.0);
}

TEST(Expert, SameSeedGivesTheSameEpisode) {
  const WorldConfig c;
  const State start = random_start_state(c, 11);
  const ExpertEpisode a = run_from("mpc", start, 11, true), b = run_from("mpc", start, 11, true);
  ASSERT_EQ(a.states.size(), b.states.size());
  for (std::size_t t = 0; t < a.states.size(); ++t) {
    ASSERT_TRUE(bit_equal(a.states[t], b.states[t])) << t;
    ASSERT_EQ(a.actions[t], b.actions[t]) << t;
  }
}

TEST(Expert, AnswersQueriesFromStatesOffItsOwnTrajectory) {
  // A DAgger-style query: a state reached by other actions, mid-episode; the expert takes over.
  const WorldConfig c;
  DiceEnv env(c);
  env.reset(3);
  for (const auto& a : test::random_actions(c, 4, 15)) env.step(a);
  auto expert = make_expert("mpc");
  expert->reset(3);
  const Action first = expert->act(env);
  for (double v : first) EXPECT_TRUE(std::isfinite(v));
  const Outcome o = run_expert_episode(*expert, env).outcome;
  EXPECT_FALSE(o.wall_contact);
  EXPECT_GE(o.steps, 15);
}

TEST(Expert, UnknownNamesAndBadConfigsAreConfigErrors) {
  EXPECT_THAT(test::error_of([] { make_expert("scriptd"); }), testing::HasSubstr("known: scripted, mpc"));
  EXPECT_THROW(make_expert("nope"), ConfigError);
  ExpertConfig bad;
  bad.search_budget = 0;
  EXPECT_THAT(test::error_of([&] { make_expert("mpc", bad); }), testing::HasSubstr("search_budget"));
  ExpertConfig dir;
  dir.swing.first_direction = 0.5;
  EXPECT_THROW(make_expert("scripted", dir), ConfigError);
  for (const auto& info : expert_list()) {
    if (info.name == "tracker") {  // follows recordings: refused without them
      EXPECT_THAT(test::error_of([] { make_expert("tracker"); }), testing::HasSubstr("needs recordings"));
      continue;
    }
    EXPECT_EQ(make_expert(info.name)->name(), info.name);
  }
}

TEST(ExpertRegistry, TrackerNeedsRecordingsAndUnknownNamesListIt) {
  EXPECT_NE(test::error_of([] { make_expert("tracker"); }).find("needs recordings"), std::string::npos);
  EXPECT_NE(test::error_of([] { make_expert("trackr"); }).find("scripted, mpc, tracker"), std::string::npos);
  EXPECT_THROW(ExpertRegistry::global().add({"mpc", "again"}, nullptr), ConfigError);
}

TEST(ExpertRegistry, AReplacedFactoryIsUsedAndCanBePutBack) {
  auto old = ExpertRegistry::global().replace(
      "scripted", [](const ExpertConfig&) -> std::unique_ptr<Expert> { throw std::logic_error("no scripted here"); });
  EXPECT_EQ(test::error_of([] { make_expert("scripted"); }), "no scripted here");
  ExpertRegistry::global().replace("scripted", std::move(old));
  EXPECT_EQ(make_expert("scripted")->name(), "scripted");
}

}  // namespace
}  // namespace dicestack

namespace dicestack {
namespace {

// Cup actions fixed in advance, one per step.
class FixedCupActions final : public Expert {
 public:
  std::string name() const override { return "fixed"; }
  Action action(int t) const { return {0.4 * std::sin(0.3 * t), 0.2 * std::cos(0.2 * t), 0.3 * std::sin(0.1 * t)}; }

 private:
  void do_reset(std::uint64_t) override {}
  Action do_act(const DiceEnv& env, const State&) override { return action(env.t()); }
};

// Told in joint torques, a cup expert moves the held cup (in free space) as its cup actions do.
TEST(Expert, ACupExpertToldInJointTorquesMovesTheHeldCupAsItsCupActionsDo) {
  WorldConfig arm;
  arm.embodiment = Embodiment::arm;
  State lifted = paper_start_state(arm);
  lifted[state_index::kCupY] += 1.5;  // clear of the dice
  const FixedCupActions cup;
  auto torques = in_joint_torques(std::make_unique<FixedCupActions>());
  EXPECT_EQ(torques->name(), "fixed");
  EXPECT_EQ(torques->controller(), ActionKind::joint_torque);
  DiceEnv held(arm), reference(arm);
  held.reset_to(lifted);
  for (int t = 0; t < 15; ++t) {
    reference.restore(held.snapshot());
    const Action a = torques->act(held);
    ASSERT_EQ(a.kind(), ActionKind::joint_torque);
    const State want = reference.step(cup.action(t)).observation, got = held.step(a).observation;
    for (std::size_t k : {state_index::kCupVx, state_index::kCupVy, state_index::kCupW})
      EXPECT_NEAR(got[k], want[k], 0.05) << "step " << t << ", number " << k;
  }
  // Telling an action in torques leaves the environment exactly where it was.
  const State before = held.get_state();
  const int t = held.t();
  EXPECT_EQ(told_in_torques(held, cup.action(3)).kind(), ActionKind::joint_torque);
  EXPECT_TRUE(test::bit_equal(held.get_state(), before));
  EXPECT_EQ(held.t(), t);
  DiceEnv floating{WorldConfig{}};
  EXPECT_THROW(torques->act(floating), InputError);
  EXPECT_THROW(told_in_torques(floating, cup.action(0)), InputError);
  ExpertConfig config;
  config.controller = ActionKind::joint_torque;
  EXPECT_EQ(make_expert("scripted", config)->controller(), ActionKind::joint_torque);
}

}  // namespace
}  // namespace dicestack
