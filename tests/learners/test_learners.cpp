#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/core/expert.hpp>

#include <dicestack/test/requests.hpp>
#include <dicestack/test/helpers.hpp>

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

TEST(Learners, BehaviourCloningEqualsFittingTheRegressorOnTheDemonstrations) {
  const DemoSet set = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext c;
  c.demos = set.episodes;
  c.regressor = "linear_svr";
  c.seed = 5;
  const LearnResult r = LearnerRegistry::global().create("bc")->learn(c);
  const Dataset d = make_dataset(set.episodes);
  const Model direct = Model::train(RegressorRegistry::global().create("linear_svr"), d.x, d.y, 5);
  EXPECT_EQ(r.model->predict(d.x), direct.predict(d.x));
}

TEST(Learners, UnknownNamesAndEmptyDemosAreRejected) {
  EXPECT_THAT(test::error_of([] { LearnerRegistry::global().create("dagr"); }), ::testing::HasSubstr("unknown learner \"dagr\"; registered: bc"));
  LearnContext c;
  c.regressor = "knn";
  EXPECT_THROW(LearnerRegistry::global().create("bc")->learn(c), InputError);
  c.demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good").episodes;
  c.regressor = "nope";
  EXPECT_THROW(LearnerRegistry::global().create("bc")->learn(c), ConfigError);
}

}  // namespace
}  // namespace dicestack

#include <dicestack/learners/record.hpp>

namespace dicestack {
namespace {

LearnContext small_context(int threads) {
  LearnContext c;
  c.world.episode.max_steps = 60;
  c.regressor = "knn";
  c.seed = 11;
  c.threads = threads;
  return c;
}

TEST(Record, ExpertEpisodesAreSeededAndThreadIndependent) {
  WorldConfig w;
  w.episode.max_steps = 80;
  const auto a = record_expert("scripted", {}, w, test::record_request(4, 3, 1)), b = record_expert("scripted", {}, w, test::record_request(4, 3, 2));
  ASSERT_EQ(a.size(), 4u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].states, b[i].states);
    EXPECT_EQ(a[i].actions, b[i].actions);
    EXPECT_EQ(a[i].sources.front(), StepSource::expert);
  }
  EXPECT_THROW(record_expert("nobody", {}, w, test::record_request(1, 0, 1)), ConfigError);
}

TEST(Dagger, BetaOneOnlyLetsTheExpertAct) {
  LearnContext c = small_context(2);
  const auto learner = LearnerRegistry::global().create(
      "dagger", {"iterations=1", "rollouts=3", "beta=1", "include_demos=false", "expert=scripted"});
  c.checkpoint_dir = test::scratch_path("dicestack_dagger_beta1");
  std::filesystem::remove_all(c.checkpoint_dir);
  const LearnResult r = learner->learn(c);
  const DemoSet data = read_demo_set(c.checkpoint_dir / "data-1");
  ASSERT_EQ(data.episodes.size(), 3u);
  for (const auto& e : data.episodes)
    for (auto s : e.sources) ASSERT_EQ(s, StepSource::expert);
  // The expert's own episodes from the same starts: the labels are exactly its actions.
  DiceEnv env(c.world);
  auto expert = make_expert("scripted");
  const std::uint64_t seed = training_start_seed(derive_seed(c.seed, 1), 0);
  env.reset_to(random_start_state(c.world, seed), seed);
  expert->reset(seed);
  const ExpertEpisode run = run_expert_episode(*expert, env, true);
  EXPECT_EQ(data.episodes[0].actions, run.actions);
  std::filesystem::remove_all(c.checkpoint_dir);
}

TEST(Dagger, LearnerActsWhenBetaIsZeroAndResultsIgnoreThreads) {
  const std::vector<std::string> opts{"iterations=2", "rollouts=3", "beta=0", "expert=scripted"};
  const DemoSet demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext one = small_context(1), two = small_context(2);
  one.demos = two.demos = demos.episodes;
  const LearnResult a = LearnerRegistry::global().create("dagger", opts)->learn(one);
  const LearnResult b = LearnerRegistry::global().create("dagger", opts)->learn(two);
  const Dataset probe = make_dataset(demos.episodes);
  EXPECT_EQ(a.model->predict(probe.x), b.model->predict(probe.x));
  ASSERT_EQ(a.curve.size(), 2u);
  EXPECT_EQ(a.curve[1].dataset_rows, b.curve[1].dataset_rows);
  EXPECT_GT(a.curve[1].dataset_rows, a.curve[0].dataset_rows);
}

TEST(Dagger, ResumeEqualsUninterrupted) {
  const DemoSet demos = read_demo_set(std::filesystem::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good");
  LearnContext c = small_context(2);
  c.demos = demos.episodes;
  const auto dir = test::scratch_path("dicestack_dagger_resume");
  std::filesystem::remove_all(dir);
  const LearnResult whole = LearnerRegistry::global().create("dagger", {"iterations=3", "rollouts=2", "expert=scripted"})->learn(c);
  // Run two rounds (as if killed after round 2), then resume to three.
  c.checkpoint_dir = dir;
  LearnerRegistry::global().create("dagger", {"iterations=2", "rollouts=2", "expert=scripted"})->learn(c);
  c.resume = true;
  const LearnResult resumed = LearnerRegistry::global().create("dagger", {"iterations=3", "rollouts=2", "expert=scripted"})->learn(c);
  const Dataset probe = make_dataset(demos.episodes);
  EXPECT_EQ(resumed.model->predict(probe.x), whole.model->predict(probe.x));
  ASSERT_EQ(resumed.curve.size(), 3u);
  EXPECT_EQ(resumed.curve.back().dataset_rows, whole.curve.back().dataset_rows);
  // Resuming with other options is refused, naming the setting and both values.
  const std::string error = test::error_of([&] {
    LearnerRegistry::global().create("dagger", {"iterations=4", "rollouts=3", "expert=scripted"})->learn(c);
  });
  EXPECT_THAT(error, ::testing::HasSubstr(
                         "dagger.json: cannot resume a run made with other settings: option rollouts \"2\" in the "
                         "checkpoint, \"3\" in this run"));
  c.seed += 1;
  EXPECT_THAT(test::error_of([&] {
                LearnerRegistry::global().create("dagger", {"iterations=4", "rollouts=2", "expert=scripted"})->learn(c);
              }),
              ::testing::HasSubstr("seed \"11\" in the checkpoint, \"12\" in this run"));
  std::filesystem::remove_all(dir);
}

TEST(Checkpoint, CleanupRemovesOnlyOurOwnOlderDataFolders) {
  LearnContext c = small_context(2);
  c.checkpoint_dir = std::filesystem::temp_directory_path() / ("dicestack_checkpoint_user_" + std::to_string(getpid()));
  std::filesystem::remove_all(c.checkpoint_dir);
  std::filesystem::create_directories(c.checkpoint_dir / "data-notes");
  std::filesystem::create_directories(c.checkpoint_dir / "data-7");
  { std::ofstream(c.checkpoint_dir / "data-notes" / "notes.txt") << "mine"; }
  { std::ofstream(c.checkpoint_dir / "data-7" / "notes.txt") << "mine"; }
  LearnerRegistry::global().create("dagger", {"iterations=2", "rollouts=2", "beta=1", "include_demos=false", "expert=scripted"})->learn(c);
  EXPECT_TRUE(std::filesystem::exists(c.checkpoint_dir / "data-notes" / "notes.txt")) << "a user's folder is kept";
  EXPECT_TRUE(std::filesystem::exists(c.checkpoint_dir / "data-7" / "notes.txt")) << "not a dicestack set: kept";
  EXPECT_FALSE(std::filesystem::exists(c.checkpoint_dir / "data-1")) << "our own older data is removed";
  EXPECT_EQ(read_demo_set(c.checkpoint_dir / "data-2").episodes.size(), 4u);
  std::filesystem::remove_all(c.checkpoint_dir);
}

TEST(Checkpoint, EditedStatesAreRefusedNamingTheFieldAndVersionOneResumes) {
  LearnContext c = small_context(2);
  c.checkpoint_dir = std::filesystem::temp_directory_path() / ("dicestack_checkpoint_edit_" + std::to_string(getpid()));
  std::filesystem::remove_all(c.checkpoint_dir);
  const std::vector<std::string> options{"iterations=1", "rollouts=2", "beta=1", "include_demos=false", "expert=scripted"};
  LearnerRegistry::global().create("dagger", options)->learn(c);
  const auto path = c.checkpoint_dir / "dagger.json";
  nlohmann::json saved;
  std::ifstream(path) >> saved;
  EXPECT_EQ(saved.at("version"), 4);
  c.resume = true;
  auto resume_with = [&](const nlohmann::json& state) {
    { std::ofstream(path) << state.dump(); }
    return test::error_of([&] { LearnerRegistry::global().create("dagger", options)->learn(c); });
  };
  auto edited = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json j = saved;
    j[nlohmann::json::json_pointer(pointer)] = value;
    return resume_with(j);
  };
  using ::testing::HasSubstr;
  using ::testing::Not;
  EXPECT_THAT(edited("/version", 5), HasSubstr("dagger.json: format version 5 is newer than this dicestack reads (4)"));
  EXPECT_THAT(edited("/version", 1.5), HasSubstr("dagger.json: field \"version\" must be an integer"));
  EXPECT_THAT(edited("/iteration", "one"), HasSubstr("field \"iteration\" must be an integer in [0, 1000000], got \"one\""));
  EXPECT_THAT(edited("/iteration", -1), HasSubstr("field \"iteration\""));
  EXPECT_THAT(edited("/data", "../../etc"), HasSubstr("field \"data\" must be a file name inside the checkpoint folder"));
  EXPECT_THAT(edited("/data", "data-7"), HasSubstr("field \"data\" must name this iteration's folder \"data-1\""));
  EXPECT_THAT(edited("/curve/0/deviation", "x"), HasSubstr("field \"curve[0].deviation\" must be a finite number"));
  EXPECT_THAT(edited("/curve", 5), HasSubstr("field \"curve\" must be an array"));
  EXPECT_THAT(edited("/format", "dicestack-model"), HasSubstr("dagger.json: not a checkpoint state"));
  // The tracker's options mean nothing to a run whose expert is another: not compared.
  nlohmann::json other = saved;
  other["run"]["learner_options"]["tracker_paths"] = "7";
  other["run"]["learner_options"].erase("tracker_shrink");
  EXPECT_EQ(resume_with(other), "");
  // A checkpoint of the tracker (so this run differs in its expert, and its tracker options count).
  nlohmann::json tracked = saved;
  tracked["run"]["learner_options"]["expert"] = "tracker";
  EXPECT_THAT(resume_with(tracked), HasSubstr("option expert \"tracker\" in the checkpoint, \"scripted\" in this run"));
  // Written when tracker_paths defaulted to 3, which -1 now means for this run's map.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_paths"], "-1");
  tracked["run"]["learner_options"]["tracker_paths"] = "3";
  EXPECT_THAT(resume_with(tracked), Not(HasSubstr("tracker_paths")));
  tracked["run"]["learner_options"]["tracker_paths"] = "1";
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_paths \"1\" in the checkpoint, \"-1\" in this run"));
  // Written before tracker_shrink existed, when the tracker never narrowed a path.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_shrink"], "5");
  tracked["run"]["learner_options"]["tracker_paths"] = "-1";
  tracked["run"]["learner_options"].erase("tracker_shrink");
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_shrink \"(absent)\" in the checkpoint, \"5\" in this run"));
  // Written before retry existed: its absence meant no retries, which auto means for this map
  // (state); "false" means the same, "true" does not.
  EXPECT_EQ(saved["run"]["learner_options"]["retry"], "auto");
  nlohmann::json retried = saved;
  retried["run"]["learner_options"].erase("retry");
  EXPECT_EQ(resume_with(retried), "");
  retried["run"]["learner_options"]["retry"] = "false";
  EXPECT_EQ(resume_with(retried), "");
  retried["run"]["learner_options"]["retry"] = "true";
  EXPECT_THAT(resume_with(retried), HasSubstr("option retry \"true\" in the checkpoint, \"auto\" in this run"));
  nlohmann::json v2 = saved;  // version 2: the learner's options joined into one string, the --set text
  v2["version"] = 2;
  v2["run"].erase("regressor_params");
  v2["run"]["regressor_sets"] = "";
  std::string joined;
  for (const auto& [k, v] : saved["run"]["learner_options"].items()) joined += (joined.empty() ? "" : ", ") + k + "=" + v.get<std::string>();
  v2["run"]["learner_options"] = joined;
  EXPECT_EQ(resume_with(v2), "");
  v2["run"]["learner_options"] = "iterations=1, rollouts=5";
  EXPECT_THAT(resume_with(v2), HasSubstr("option rollouts \"5\" in the checkpoint, \"2\" in this run"));
  nlohmann::json v1 = v2;  // version 1: the same state without "version"
  v1["run"]["learner_options"] = joined;
  v1.erase("version");
  EXPECT_EQ(resume_with(v1), "");
  std::filesystem::remove(path);  // a folder where the state should be: the system's reason
  std::filesystem::create_directory(path);
  EXPECT_EQ(test::error_of([&] { LearnerRegistry::global().create("dagger", options)->learn(c); }),
            path.string() + ": read failed: Is a directory");
  std::filesystem::remove_all(c.checkpoint_dir);
}

TEST(Checkpoint, RegressorSettingsCompareAsParsedValuesInEveryVersion) {
  LearnContext c = small_context(2);
  c.checkpoint_dir = test::scratch_path("dicestack_checkpoint_sets");
  std::filesystem::remove_all(c.checkpoint_dir);
  const std::vector<std::string> options{"iterations=1", "rollouts=2", "beta=1", "include_demos=false", "expert=scripted"};
  c.regressor_sets = {"k=2", "rotate=true"};
  LearnerRegistry::global().create("dagger", options)->learn(c);
  const auto path = c.checkpoint_dir / "dagger.json";
  nlohmann::json saved;
  std::ifstream(path) >> saved;
  EXPECT_EQ(saved["run"]["regressor_params"]["k"], 2);
  EXPECT_EQ(saved["run"]["regressor_params"]["metric"], "l2") << "every parameter, defaults included";
  EXPECT_FALSE(saved["run"].contains("regressor_sets"));
  c.resume = true;
  auto resume_with = [&](const nlohmann::json& state, std::vector<std::string> sets) {
    { std::ofstream(path) << state.dump(); }
    c.regressor_sets = std::move(sets);
    return test::error_of([&] { LearnerRegistry::global().create("dagger", options)->learn(c); });
  };
  using ::testing::HasSubstr;
  // Another spelling of the same values resumes; a default given explicitly is the same setting.
  EXPECT_EQ(resume_with(saved, {"k=02", "rotate=1"}), "");
  EXPECT_EQ(resume_with(saved, {"k=2", "metric=l2"}), "");
  // A real difference is refused naming the parameter and both values.
  const std::string refused = resume_with(saved, {"k=3", "metric=l1"});
  EXPECT_THAT(refused, HasSubstr("dagger.json: cannot resume a run made with other settings"));
  EXPECT_THAT(refused, HasSubstr("regressor parameter k 2 in the checkpoint, 3 in this run"));
  EXPECT_THAT(refused, HasSubstr("regressor parameter metric \"l2\" in the checkpoint, \"l1\" in this run"));
  // A parameter the checkpoint does not name had its default then.
  nlohmann::json fewer = saved;
  fewer["run"]["regressor_params"].erase("leaf_size");
  EXPECT_EQ(resume_with(fewer, {"k=2"}), "");
  EXPECT_THAT(resume_with(fewer, {"k=2", "leaf_size=7"}), HasSubstr("regressor parameter leaf_size 20 in the checkpoint, 7 in this run"));
  // Version 3 (and before): the --set text, parsed through the schema.
  nlohmann::json v3 = saved;
  v3["version"] = 3;
  v3["run"].erase("regressor_params");
  v3["run"]["regressor_sets"] = "k=2 rotate=true";
  EXPECT_EQ(resume_with(v3, {"k=002", "rotate=1"}), "");
  EXPECT_THAT(resume_with(v3, {"k=4"}), HasSubstr("regressor parameter k 2 in the checkpoint, 4 in this run"));
  v3["run"]["regressor_sets"] = "";
  EXPECT_EQ(resume_with(v3, {"k=3"}), "") << "no --set then: the defaults";
  EXPECT_THAT(resume_with(v3, {"k=2"}), HasSubstr("regressor parameter k 3 in the checkpoint, 2 in this run"));
  v3["run"]["regressor_sets"] = "k=many";
  EXPECT_THAT(resume_with(v3, {"k=2"}), HasSubstr("regressor settings \"k=many\" in the checkpoint, which this dicestack refuses"));
  // Another regressor is one difference, not one per parameter.
  c.regressor = "gbt";
  const std::string other = resume_with(saved, {});
  EXPECT_THAT(other, HasSubstr("regressor \"knn\" in the checkpoint, \"gbt\" in this run"));
  EXPECT_THAT(other, ::testing::Not(HasSubstr("regressor parameter")));
  std::filesystem::remove_all(c.checkpoint_dir);
}

}  // namespace
}  // namespace dicestack
