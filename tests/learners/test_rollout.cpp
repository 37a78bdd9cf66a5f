// rollout(): what a policy is shown (its history, the actions the world applied) and what is
// recorded (the clean action, whatever noise ran).
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include <dicestack/core/env.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

// Records what it was shown, and acts with a fixed pattern.
class Probe final : public Policy {
 public:
  std::vector<std::size_t> ts, action_counts;
  std::vector<State> starts;
  Action act(const History& h) override {
    ts.push_back(h.t());
    action_counts.push_back(h.actions.size());
    starts.push_back(h.start());
    return {h.t() % 2 ? 5.0 : -0.3, 0.1, 0.0};  // 5 m/s is beyond the limit: the world clips it
  }
  std::string name() const override { return "probe"; }
};

TEST(Rollout, PoliciesSeeTheirHistoryAndTheActionsTheWorldApplied) {
  const WorldConfig w = test::short_world();
  DiceEnv env(w);
  Probe p;
  const State start = random_start_state(w, 3);
  const Episode e = rollout(env, p, start, 3, StepSource::policy);
  ASSERT_EQ(p.ts.size(), e.size());
  for (std::size_t t = 0; t < e.size(); ++t) {
    EXPECT_EQ(p.ts[t], t);
    EXPECT_EQ(p.action_counts[t], t);
    EXPECT_EQ(p.starts[t], e.states.front());
    EXPECT_LE(e.actions[t][0], w.action.limit[0]);  // recorded as applied: clipped
  }
}

TEST(Rollout, NoiseIsExecutedButTheCleanActionIsRecorded) {
  const WorldConfig w = test::short_world();
  DiceEnv a(w), b(w);
  auto expert = make_expert("scripted");
  ExpertPolicy pa(*expert, a);
  PerturbedEnv noisy(b);
  noisy.add_executed_noise({0.2, 0.02, 0.1}, 9);
  const State start = random_start_state(w, 4);
  const Episode clean = rollout(a, pa, start, 4, StepSource::expert);
  ExpertPolicy pb(*expert, b);
  const Episode perturbed = rollout(noisy, pb, start, 4, StepSource::expert);
  EXPECT_NE(clean.states[10], perturbed.states[10]);
  // The recorded labels are what the expert chose in the states it was in, not what ran.
  DiceEnv replay(w);
  replay.reset_to(start, 4);
  expert->reset(4);
  EXPECT_EQ(perturbed.actions[0], expert->act(replay));
  const StepResult r = replay.step(perturbed.actions[0]);
  EXPECT_NE(r.observation, perturbed.states[1]);  // the executed action differed
}

}  // namespace
}  // namespace dicestack
