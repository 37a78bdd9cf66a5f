// Perturbed episodes: evaluation and rollouts in a perturbed world (delays, noise, randomised
// physics), the same on any thread count, what the policy is shown, and experts that plan for it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/policies.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using test::Watcher;
using test::watcher;

TEST(Perturbed, NoneIsTodaysEvaluationByteForByte) {
  // Today's evaluation, by hand: each start from its seed in the nominal world, one rollout.
  const WorldConfig w = test::short_world(50);
  std::vector<Episode> eps;
  EvalRequest r = test::eval_request(4, 21, 2, &eps);
  r.perturbation = perturbation_level("none");
  evaluate(watcher, w, r);
  DiceEnv env(w);
  for (std::size_t i = 0; i < eps.size(); ++i) {
    Watcher p;
    const std::uint64_t seed = evaluation_start_seed(21, i);
    const Episode e = rollout(env, p, random_start_state(w, seed), seed, StepSource::policy);
    ASSERT_EQ(e.states.size(), eps[i].states.size());
    for (std::size_t t = 0; t < e.states.size(); ++t) ASSERT_TRUE(test::bit_equal(e.states[t], eps[i].states[t]));
    EXPECT_EQ(e.actions, eps[i].actions);
  }
}

TEST(Perturbed, EvaluationIsTheSameOnAnyThreadCountAndDiffersFromNominal) {
  const WorldConfig w = test::short_world(50);
  std::vector<Episode> one, two, nominal;
  EvalRequest r = test::eval_request(4, 5, 1, &one);
  r.perturbation = perturbation_level("hard");
  evaluate(watcher, w, r);
  r.threads = 2;
  r.rollouts = &two;
  evaluate(watcher, w, r);
  evaluate(watcher, w, test::eval_request(4, 5, 2, &nominal));
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states) << i;
    EXPECT_NE(one[i].states, nominal[i].states) << i;
  }
}

TEST(Perturbed, AnExpertPlansInEachEpisodesOwnWorldOnAnyThreadCount) {
  // An expert keeps its planning simulator between episodes; each perturbed episode must plan
  // in its own world, not in the first one the thread happened to run.
  const WorldConfig w = test::short_world(40);
  const PolicyFactory mpc = [] { return std::make_unique<OwnedExpertPolicy>(make_expert("mpc", ExpertConfig{})); };
  std::vector<Episode> one, two;
  EvalRequest r = test::eval_request(4, 2, 1, &one);
  r.perturbation = perturbation_factor("dice_mass", "hard");
  evaluate(mpc, w, r);
  r.threads = 2;
  r.rollouts = &two;
  evaluate(mpc, w, r);
  for (std::size_t i = 0; i < one.size(); ++i) EXPECT_EQ(one[i].states, two[i].states) << i;
}

TEST(Perturbed, AnExpertInJointTorquesMeetsTheirDelayNoiseAndBiasTheSameOnAnyThreadCount) {
  WorldConfig w = test::short_world(30);
  w.embodiment = Embodiment::arm;
  ExpertConfig torques;
  torques.controller = ActionKind::joint_torque;
  const PolicyFactory scripted = [torques] { return std::make_unique<OwnedExpertPolicy>(make_expert("scripted", torques)); };
  std::vector<Episode> one, two, nominal;
  EvalRequest r = test::eval_request(3, 8, 1, &one);
  r.actions = ActionKind::joint_torque;
  r.perturbation = perturbation_factor("action_noise", "medium");
  r.perturbation.action_delay = 2;
  evaluate(scripted, w, r);
  r.threads = 2;
  r.rollouts = &two;
  evaluate(scripted, w, r);
  EvalRequest clean = test::eval_request(3, 8, 2, &nominal);
  clean.actions = ActionKind::joint_torque;
  evaluate(scripted, w, clean);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states) << i;
    EXPECT_NE(one[i].states, nominal[i].states) << i;
    EXPECT_NE(one[i].perturbation.find("joint_torque_noise_std"), std::string::npos) << "its record names the torques' draws";
  }
}

// A draw with nothing on but what the caller sets next.
PerturbationDraw bare_draw(const WorldConfig& w) {
  PerturbationDraw d = draw_perturbation(Perturbation{}, w, 1);
  d.acts = true;
  return d;
}

// One rollout of `p` in the world `w` with only what `d` sets perturbed.
Episode perturbed_rollout(const WorldConfig& w, const PerturbationDraw& d, Policy& p, std::uint64_t seed = 1) {
  DiceEnv env(w);
  PerturbedEnv episode(env, d);
  return rollout(episode, p, random_start_state(w, seed), seed, StepSource::policy);
}

TEST(Perturbed, ObservationDelayShowsOlderStates) {
  const WorldConfig w = test::short_world(30);
  PerturbationDraw d = bare_draw(w);
  d.observation_delay = 3;
  Watcher p;
  const Episode e = perturbed_rollout(w, d, p);
  ASSERT_EQ(p.seen.size(), e.actions.size());
  for (std::size_t t = 0; t < p.seen.size(); ++t) EXPECT_EQ(p.seen[t], e.states[t >= 3 ? t - 3 : 0]) << t;
}

// The Watcher's swing, writing down the row and label `map` makes of what it is shown.
class RowWatcher final : public Policy {
 public:
  explicit RowWatcher(const FeatureMap& map) : map_(map) {}
  Action act(const History& h) override {
    const Action a = watch_.act(h);
    rows.emplace_back(map_.width());
    map_.compute(h, rows.back());
    labels.emplace_back(kActionDim);
    map_.label(h, a, labels.back());
    return a;
  }
  std::string name() const override { return "row-watcher"; }
  std::vector<std::vector<double>> rows, labels;

 private:
  const FeatureMap& map_;
  Watcher watch_;
};

TEST(Perturbed, TrainingRowsShowWhatTheRolloutShowedThePolicy) {
  const WorldConfig w = test::short_world(30);
  PerturbationDraw d = bare_draw(w);
  for (std::size_t k = 0; k < kStateDim; ++k) d.observation_noise[k] = 0.05 * observation_spread()[k];
  d.observation_delay = 2;
  d.action_delay = 1;
  d.action_noise = {0.05, 0.05, 0.05};
  d.noise_seed = 99;
  for (const char* name : {"state+clock+start_state/velocity", "state+clock/velocity/ahead", "state/position/ahead", "state"}) {
    const FeatureMap& map = feature_map(name);
    RowWatcher p(map);
    DiceEnv env(w);
    PerturbedEnv episode(env, d);
    // Labelled as an expert's steps: what a learner chose under a delay is not rebuilt.
    Episode e = rollout(episode, p, random_start_state(w, 1), 1, StepSource::expert);
    const Dataset rows = make_dataset({e}, map);
    ASSERT_EQ(static_cast<std::size_t>(rows.x.rows()), p.rows.size()) << name;
    for (std::size_t t = 0; t < p.rows.size(); ++t) {
      for (std::size_t k = 0; k < map.width(); ++k)
        ASSERT_EQ(rows.x(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(k)), p.rows[t][k]) << name << " " << t << " " << k;
      for (std::size_t k = 0; k < kActionDim; ++k)
        ASSERT_EQ(rows.y(static_cast<Eigen::Index>(t), static_cast<Eigen::Index>(k)), p.labels[t][k]) << name << " " << t << " " << k;
    }
    e.perturbation.clear();  // negative control: the true states are other rows
    EXPECT_NE(make_dataset({e}, map).x, rows.x) << name;
  }
}

TEST(Perturbed, ActionDelayExecutesNothingUntilTheFirstChoiceArrives) {
  const WorldConfig w = test::short_world(30);
  PerturbationDraw d = bare_draw(w);
  d.action_delay = 4;
  DiceEnv env(w), plain(w);
  PerturbedEnv delayed(env, d);
  Watcher p, q;
  const State start = random_start_state(w, 1);
  const Episode late = rollout(delayed, p, start, 1, StepSource::policy);
  const Episode now = rollout(plain, q, start, 1, StepSource::policy);
  // Doing nothing for 4 steps is not what the policy chose: the states part.
  EXPECT_NE(late.states[5], now.states[5]);
  // The first 4 steps are the world left alone.
  DiceEnv idle(w);
  idle.reset_to(start, 1);
  State s{};
  for (int t = 0; t < 4; ++t) s = idle.step({0.0, 0.0, 0.0}).observation;
  EXPECT_TRUE(test::bit_equal(s, late.states[4]));
}

// Chooses a different action each step and remembers what it was told runs before it.
class PendingWatcher final : public Policy {
 public:
  Action act(const History& h) override {
    pending.emplace_back(h.pending.begin(), h.pending.end());
    return {0.01 * static_cast<double>(h.t() + 1), 0.0, 0.0};
  }
  std::string name() const override { return "pending watcher"; }
  std::vector<std::vector<Action>> pending;
};

TEST(Perturbed, PendingHoldsWhatRunsBeforeTheChoiceInOrder) {
  const WorldConfig w = test::short_world(12);
  PerturbationDraw d = bare_draw(w);
  d.action_delay = 3;
  PendingWatcher p;
  const Episode e = perturbed_rollout(w, d, p);
  ASSERT_EQ(p.pending.size(), e.actions.size());
  for (std::size_t t = 0; t < p.pending.size(); ++t) {
    ASSERT_EQ(p.pending[t].size(), 3u) << t;
    for (std::size_t k = 0; k < 3; ++k) {  // the choice of step t - 3 + k, zeros before step 0
      const double chosen = t + k >= 3 ? 0.01 * static_cast<double>(t + k - 3 + 1) : 0.0;
      EXPECT_EQ(p.pending[t][k][0], chosen) << t << " " << k;
    }
  }
  PendingWatcher q;  // no delay: nothing pending
  DiceEnv env(w);
  rollout(env, q, random_start_state(w, 1), 1, StepSource::policy);
  for (const auto& v : q.pending) EXPECT_TRUE(v.empty());
}

// Does nothing for `idle` steps, then lets the expert act with no delay.
class IdleThenExpert final : public Policy {
 public:
  IdleThenExpert(std::unique_ptr<Expert> expert, std::size_t idle) : expert_(std::move(expert)), idle_(idle) {}
  void attach(const DiceEnv& env) override { expert_.attach(env); }
  void reset(std::uint64_t seed) override { expert_.reset(seed); }
  Action act(const History& h) override { return h.t() < idle_ ? Action{0.0, 0.0, 0.0} : expert_.act(h); }
  std::string name() const override { return "idle then expert"; }

 private:
  OwnedExpertPolicy expert_;
  std::size_t idle_;
};

// An mpc search small enough for a unit test.
ExpertConfig quick_search() {
  ExpertConfig c;
  c.search_budget = 8;
  c.replan_budget = 4;
  return c;
}

// Two episodes through the same states, bit for bit.
void expect_same_states(const Episode& a, const Episode& b, const std::string& what) {
  ASSERT_EQ(a.states.size(), b.states.size()) << what;
  for (std::size_t t = 0; t < a.states.size(); ++t) ASSERT_TRUE(test::bit_equal(a.states[t], b.states[t])) << what << " " << t;
}

TEST(Perturbed, AnExpertUnderActionDelayActsForTheStateItsActionLandsIn) {
  // With the simulator as its model (a Smith predictor), an expert whose actions run 4 steps
  // late moves the world exactly as the same expert with no delay does once 4 idle steps have
  // passed: the same states, bit for bit, and the same outcome.
  const WorldConfig w = test::short_world(40);
  const ExpertConfig c = quick_search();
  PerturbationDraw d = bare_draw(w);
  d.action_delay = 4;
  for (std::uint64_t seed : {1, 2}) {
    const State start = random_start_state(w, seed);
    DiceEnv env(w), plain(w);
    PerturbedEnv delayed(env, d);
    OwnedExpertPolicy late(make_expert("mpc", c));
    IdleThenExpert idle(make_expert("mpc", c), 4);
    const Episode a = rollout(delayed, late, start, seed, StepSource::expert);
    const Episode b = rollout(plain, idle, start, seed, StepSource::expert);
    expect_same_states(a, b, "seed " + std::to_string(seed));
    // Fed the observations (here the true states), its feedback is moved through what is
    // pending as the world is: the same episode.
    DiceEnv sensing_env(w);
    PerturbedEnv sensing_delayed(sensing_env, d);
    OwnedExpertPolicy sensing(make_expert("mpc", c), ExpertFeedback::observations);
    expect_same_states(rollout(sensing_delayed, sensing, start, seed, StepSource::expert), a,
                       "observations, seed " + std::to_string(seed));
    EXPECT_EQ(a.outcome.realistic_success(), b.outcome.realistic_success());
    EXPECT_EQ(a.outcome.wall_contact, b.outcome.wall_contact);
  }
}

TEST(Perturbed, AnExpertsFeedbackOnTheObservationsIsItsOwnWhereTheyAreTrueAndMovesWithTheirNoise) {
  // Told to act on what a policy is shown, an expert's feedback reads the observations while
  // its choices read the world: where the observations are the true states, the episode is the
  // world-fed expert's, bit for bit; under observation noise that expert ignores the noise and
  // the observation-fed one does not.
  const WorldConfig w = test::short_world(40);
  const ExpertConfig c = quick_search();
  PerturbationDraw noisy = bare_draw(w);
  for (std::size_t k = 0; k < kStateDim; ++k) noisy.observation_noise[k] = 0.05 * observation_spread()[k];
  for (const std::string name : {"scripted", "mpc"}) {
    OwnedExpertPolicy own(make_expert(name, c)), sensing(make_expert(name, c), ExpertFeedback::observations);
    const Episode nominal = perturbed_rollout(w, bare_draw(w), own);
    expect_same_states(perturbed_rollout(w, bare_draw(w), sensing), nominal, name + ", observations true");
    expect_same_states(perturbed_rollout(w, noisy, own), nominal, name + " reading the world, observations noisy");
    const Episode moved = perturbed_rollout(w, noisy, sensing);
    ASSERT_GT(moved.states.size(), 1u);
    EXPECT_FALSE(test::bit_equal(moved.states[1], nominal.states[1])) << name << ": the first noisy feedback moves the cup";
  }
}

TEST(Perturbed, AnInvalidPerturbationIsRefusedBeforeAnyRollout) {
  std::atomic<int> made{0};
  EvalRequest r = test::eval_request(3, 0, 1);
  r.perturbation.friction = 1.5;
  EXPECT_THAT(test::error_of([&] {
                evaluate([&] { ++made; return std::make_unique<Watcher>(); }, test::short_world(30), r);
              }),
              HasSubstr("\"friction\""));
  EXPECT_EQ(made, 0);
}

}  // namespace
}  // namespace dicestack
