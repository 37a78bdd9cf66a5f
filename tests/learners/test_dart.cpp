// DART: the expert's episodes under noise, randomised worlds and drawn delays, on any thread
// count, and a model file that then rolls out alone.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/requests.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// knn on the short world, seed 5, one thread: DART's test runs.
LearnContext knn_context() {
  LearnContext c;
  c.world = test::short_world();
  c.regressor = "knn";
  c.features = "state+clock+start";
  c.seed = 5;
  c.threads = 1;
  return c;
}

TEST(Dart, RecordsUnderNoiseAndIgnoresTheThreadCount) {
  const auto learner = LearnerRegistry::global().create("dart", {"episodes=4", "noise=0.2", "successes_only=false"});
  LearnContext c = knn_context();
  const LearnResult one = learner->learn(c);
  c.threads = 2;
  const LearnResult two = learner->learn(c);
  EXPECT_EQ(one.model->regressor().save_payload(), two.model->regressor().save_payload());
  EXPECT_EQ(one.model->features().name(), "state+clock+start");
  EXPECT_EQ(one.model->record.at("learner"), "dart");
  // Without noise the data are the expert's own clean episodes: a different model.
  const auto quiet = LearnerRegistry::global().create("dart", {"episodes=4", "noise=0", "successes_only=false"})->learn(c);
  // In 60 steps the expert never stacks: with the default successes_only nothing is left to fit.
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", {"episodes=2"})->learn(c); }),
              HasSubstr("dart: no demonstration to fit (the expert succeeded in none of 2 noisy episodes)"));
  EXPECT_NE(quiet.model->regressor().save_payload(), one.model->regressor().save_payload());
  EXPECT_EQ(LearnerRegistry::global().info("dart").default_features, "state+clock+start_state");
}

TEST(Dart, TrainsUnderRandomisedWorldsOnAnyThreadCount) {
  LearnContext c = knn_context();
  const auto learner = LearnerRegistry::global().create("dart", {"episodes=4", "successes_only=false", "perturb=medium"});
  const LearnResult one = learner->learn(c);
  c.threads = 2;
  const LearnResult two = learner->learn(c);
  EXPECT_EQ(one.model->regressor().save_payload(), two.model->regressor().save_payload());
  EXPECT_EQ(one.model->record.at("perturb"), "medium");
  const auto nominal = LearnerRegistry::global().create("dart", {"episodes=4", "successes_only=false"})->learn(c);
  EXPECT_NE(nominal.model->regressor().save_payload(), one.model->regressor().save_payload());
  EXPECT_FALSE(nominal.model->record.contains("perturb"));
  // DAgger's mixture rollouts take the option too.
  const std::vector<std::string> dagger{"expert=scripted", "iterations=1", "rollouts=2", "include_demos=false", "perturb=hard"};
  c.threads = 1;
  const LearnResult d1 = LearnerRegistry::global().create("dagger", dagger)->learn(c);
  c.threads = 2;
  const LearnResult d2 = LearnerRegistry::global().create("dagger", dagger)->learn(c);
  const LearnResult d0 =
      LearnerRegistry::global().create("dagger", {"expert=scripted", "iterations=1", "rollouts=2", "include_demos=false"})->learn(c);
  EXPECT_EQ(d1.model->regressor().save_payload(), d2.model->regressor().save_payload());
  EXPECT_NE(d0.model->regressor().save_payload(), d1.model->regressor().save_payload());
  EXPECT_EQ(d1.model->record.at("perturb"), "hard");
  // A bad perturbation is refused before any episode, naming the option.
  for (const char* learner_name : {"dart", "dagger"})
    EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create(learner_name, {"perturb=extreme"})->learn(c); }),
                HasSubstr(std::string(learner_name) + ": option perturb: "));
}

// Behind no estimator the expert's labels answer the world's state: a factor that keeps them from
// being a function of what the policy is shown is refused by name, before any episode.
TEST(Dart, AFactorTheExpertCannotLabelIsRefusedByName) {
  const auto through = [](Perturbation p) {
    TrainingPerturbation t;
    t.name = "a file";
    t.trained = p;
    return t;
  };
  Perturbation noise, acting, seeing;
  noise.observation_noise = 0.01;
  acting.action_delay = 2;
  seeing.observation_delay = 2;
  const FeatureMap& now = feature_map("state+clock"), &ahead = feature_map("state+clock/ahead");
  EXPECT_THAT(test::error_of([&] { require_labellable(through(noise), ahead, "dart"); }),
              HasSubstr("dart: option perturb (a file) with estimator none: observation_noise cannot be labelled"));
  EXPECT_THAT(test::error_of([&] { require_labellable(through(acting), now, "dart"); }),
              HasSubstr("action_delay cannot be labelled on the map state+clock"));
  EXPECT_THAT(test::error_of([&] { require_labellable(through(seeing), now, "dagger"); }),
              HasSubstr("dagger: option perturb (a file) with estimator none: observation_delay cannot be labelled"));
  // The row of an "/ahead" map carries what is pending and unseen: a fixed delay is labellable.
  EXPECT_NO_THROW(require_labellable(through(acting), ahead, "dart"));
  EXPECT_NO_THROW(require_labellable(through(seeing), ahead, "dart"));
  // DAgger's rows record the expert's labels of the learner's steps, not what it chose.
  EXPECT_THAT(test::error_of([&] { require_labellable(through(acting), ahead, "dagger", true); }),
              HasSubstr("dagger: option perturb (a file) with estimator none: action_delay cannot be labelled: the rollouts"));
  // The documented recipe: an action delay drawn per episode on a "/landing" map.
  acting.delays_drawn = true;
  EXPECT_NO_THROW(require_labellable(through(acting), feature_map("state+clock+start_state@dice/position/landing"), "dart"));
  // ... not on its "/ahead" form, whose clock counts the choices and not the landing step.
  EXPECT_THAT(test::error_of([&] { require_labellable(through(acting), ahead, "dart"); }),
              HasSubstr("a drawn action_delay cannot be labelled on the map state+clock/ahead"));
  EXPECT_NO_THROW(require_labellable(through(acting), feature_map("state/ahead"), "dart"));  // no clock to mislead
  seeing.delays_drawn = true;
  EXPECT_THAT(test::error_of([&] { require_labellable(through(seeing), ahead, "dart"); }),
              HasSubstr("a drawn observation_delay cannot be labelled"));
  // A level through the learner: refused before its first episode.
  LearnContext c = knn_context();
  for (const char* learner : {"dart", "dagger"})
    EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create(learner, {"perturb=medium", "estimator=none"})->learn(c); }),
                HasSubstr(std::string(learner) + ": option perturb (medium) with estimator none: observation_noise"));
}

// Behind the estimator (the default), a level's sensing factors and delays are the estimator's
// to make up: training randomises the rest, and the model names the estimator it runs behind.
TEST(Dart, ALevelWithSensingTrainsWithoutItAndTheModelNamesTheEstimator) {
  const WorldConfig w = test::short_world(60);
  const auto parsed = [&](std::vector<std::string> options) {
    const auto learner = LearnerRegistry::global().create("dart", std::move(options));
    return learner_perturbation(learner->params(), w, "dart");
  };
  const TrainingPerturbation behind = parsed({"perturb=medium"});
  Perturbation expected = perturbation_level("medium");
  expected.observation_noise = 0.0;
  expected.observation_delay = expected.action_delay = 0;
  EXPECT_EQ(behind.trained, expected);
  EXPECT_EQ(behind.estimator, "kalman");
  const TrainingPerturbation through = parsed({"perturb=medium", "estimator=none"});
  EXPECT_EQ(through.trained, perturbation_level("medium"));
  EXPECT_EQ(through.estimator, "none");
  // Nothing to estimate: no estimator named.
  const std::filesystem::path physics = test::scratch_path("physics.json");
  {
    std::ofstream f(physics);
    f << R"({"format": "dicestack-perturbation", "version": 2, "friction": 0.3})";
  }
  EXPECT_EQ(parsed({"perturb=" + physics.string()}).estimator, "none");
  std::filesystem::remove(physics);

  LearnContext c = knn_context();
  const LearnResult model = LearnerRegistry::global().create("dart", {"episodes=4", "successes_only=false", "perturb=medium"})->learn(c);
  EXPECT_EQ(model.model->record.at("estimator"), "kalman");
  EXPECT_EQ(estimator_for("", *model.model), "kalman");
  EXPECT_EQ(estimator_for("none", *model.model), "none");
  const auto nominal = LearnerRegistry::global().create("dart", {"episodes=4", "successes_only=false"})->learn(c);
  EXPECT_EQ(estimator_for("", *nominal.model), "none");
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", {"estimator=particles"}); }),
              HasSubstr("estimator"));
}

TEST(Dart, RecordedEpisodesUnderAPerturbationAreThreadIndependent) {
  const WorldConfig w = test::short_world(40);
  RecordRequest r = test::record_request(3, 8, 1);
  r.perturbation = perturbation_level("hard");
  const auto one = record_expert("scripted", {}, w, r);
  r.threads = 2;
  const auto two = record_expert("scripted", {}, w, r);
  const auto nominal = record_expert("scripted", {}, w, test::record_request(3, 8, 2));
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states);
    EXPECT_NE(one[i].states, nominal[i].states);
  }
}

TEST(Dart, DrawnDelaysDifferByEpisodeAndEachEpisodeSavesItsOwn) {
  // Domain randomisation over latency: one file, a delay per episode, the one each episode got
  // saved with it (what the dataset replays the /ahead and /landing rows from).
  const WorldConfig w = test::short_world(20);
  RecordRequest r = test::record_request(12, 5, 1);
  r.perturbation.action_delay = 3;
  r.perturbation.observation_delay = 2;
  r.perturbation.delays_drawn = true;
  const auto one = record_expert("scripted", {}, w, r);
  r.threads = 2;
  const auto two = record_expert("scripted", {}, w, r);
  std::set<long long> action, observation;
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states) << i;
    const auto drawn = nlohmann::json::parse(one[i].perturbation);
    action.insert(drawn.at("action_delay").get<long long>());
    observation.insert(drawn.at("observation_delay").get<long long>());
  }
  EXPECT_GE(action.size(), 3u);
  EXPECT_GE(*action.begin(), 0);
  EXPECT_LE(*action.rbegin(), 3);
  EXPECT_GE(observation.size(), 2u);
  EXPECT_LE(*observation.rbegin(), 2);
}

TEST(Dart, AModelFileAloneRollsOut) {
  // At evaluation only the regressor acts: the model is read back from its file, and the
  // rollout gets no expert, no simulation ahead and no snapshot (ModelPolicy sees a History).
  LearnContext c;
  c.world = test::short_world();
  c.regressor = "linear_svr";
  c.features = "state+clock+start";
  c.seed = 2;
  const auto learned = LearnerRegistry::global().create("dart", {"episodes=3", "successes_only=false"})->learn(c);
  const fs::path path = fs::temp_directory_path() / ("dicestack_dart_alone_" + std::to_string(getpid()) + ".dsm");
  save_model(*learned.model, path);
  auto model = std::make_shared<const Model>(load_model(path));
  fs::remove(path);
  const EvalStats a = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, c.world, test::eval_request(3, 0, 1));
  const EvalStats b = evaluate([&] { return std::make_unique<ModelPolicy>(learned.model); }, c.world, test::eval_request(3, 0, 2));
  EXPECT_EQ(a.episodes, 3);
  EXPECT_EQ(a.dice_in_cup_mean, b.dice_in_cup_mean);
  EXPECT_EQ(a.mean_length, b.mean_length);
}

}  // namespace
}  // namespace dicestack
