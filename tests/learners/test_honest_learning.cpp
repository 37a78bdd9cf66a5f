// Learning from recordings alone: the tracker as the expert of DART and DAgger, with
// the hand-made experts impossible to build, and a model that then acts on its own.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/demos.hpp>
#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;
using test::human_six;

// While alive, the named experts cannot be built: make_expert throws naming them.
class Forbidden {
 public:
  explicit Forbidden(std::vector<std::string> names) : names_(std::move(names)) {
    for (const auto& n : names_)
      saved_.push_back(ExpertRegistry::global().replace(n, [n](const ExpertConfig&) -> std::unique_ptr<Expert> {
        throw std::logic_error("expert " + n + " was built");
      }));
  }
  ~Forbidden() {
    for (std::size_t i = 0; i < names_.size(); ++i) ExpertRegistry::global().replace(names_[i], std::move(saved_[i]));
  }

 private:
  std::vector<std::string> names_;
  std::vector<ExpertRegistry::Factory> saved_;
};

LearnContext recordings_context() {
  LearnContext c;
  c.world = WorldConfig{};
  c.demos = human_six();
  c.regressor = "linear_svr";
  c.features = "state+clock+start_state";
  c.seed = 3;
  c.threads = 2;
  return c;
}

TEST(HonestLearning, DartFromRecordingsBuildsNoHandMadeExpert) {
  const Forbidden no({"mpc", "scripted"});
  EXPECT_THAT(test::error_of([] { make_expert("mpc"); }), HasSubstr("expert mpc was built"));
  const LearnContext c = recordings_context();
  const auto learned = LearnerRegistry::global()
                           .create("dart", {"expert=tracker", "episodes=3", "successes_only=false", "tracker_probes=1",
                                            "tracker_optimise=false", "tracker_refine=0"})
                           ->learn(c);
  EXPECT_EQ(learned.model->record.at("expert"), "tracker");
  EXPECT_EQ(learned.model->record.at("learner"), "dart");
  EXPECT_EQ(learned.model->record.at("tracker_paths"), "3") << "the default resolved for a map answering impulses";
  // The options as the run used them, each default that depends on the expert or the map resolved.
  EXPECT_EQ(learned.model->record.at("dart_settings"),
            "expert=tracker, episodes=3, noise=0.1/0.5/0.2, replan=false, retry=false, mpc_robust=0, successes_only=false, "
            "include_demos=false");
  // The three best-ranked paths (a recording, or a recording smoothed otherwise), each with its
  // score out of 1 probe x (1 + 5 noisy trials), or, a finalist, 1 + 4 probes.
  const std::string followed = learned.model->record.at("tracker_followed");
  const std::string path = "[a-z_0-9]+( \\(smoothed [0-9]+\\))? \\(([0-6] of 6|[0-9]+ of 30) probe trials\\)";
  EXPECT_THAT(followed, testing::MatchesRegex(path + "(, " + path + "){2}"));
  EXPECT_TRUE(std::any_of(c.demos.begin(), c.demos.end(), [&](const Episode& e) { return followed.starts_with(e.name + " "); }))
      << followed << " does not start with a recording of the set";
  EXPECT_EQ(tracker_paths_for(-1, "state+clock+start_state/position"), 1);
  EXPECT_EQ(tracker_paths_for(-1, "state/velocity"), 3);
  EXPECT_EQ(tracker_paths_for(5, "state/position"), 5);
}

TEST(HonestLearning, DadAndDartFromThreeRecordingsBuildNoHandMadeExpertAndNameTheirRecordings) {
  const Forbidden no({"mpc", "scripted"});
  LearnContext c = recordings_context();
  c.demos.resize(3);
  c.features = "state+clock+start_state@dice+retry/position";
  const std::vector<std::string> tracker{"tracker_probes=1", "tracker_robust=1", "tracker_variants=false",
                                         "tracker_refine=0"};
  std::vector<std::string> dad{"starts=training", "episodes=2", "windows=1", "iterations=1", "corrector=track"};
  dad.insert(dad.end(), tracker.begin(), tracker.end());
  const auto from_dad = LearnerRegistry::global().create("dad", dad)->learn(c);
  EXPECT_EQ(from_dad.model->record.at("dad_starts"), "training");
  std::vector<std::string> dart{"expert=tracker", "episodes=2", "successes_only=false"};
  dart.insert(dart.end(), tracker.begin(), tracker.end());
  const auto from_dart = LearnerRegistry::global().create("dart", dart)->learn(c);
  for (const auto* model : {from_dad.model.get(), from_dart.model.get()}) {
    const std::string followed = model->record.at("tracker_followed");
    EXPECT_TRUE(std::any_of(c.demos.begin(), c.demos.end(), [&](const Episode& e) { return followed.starts_with(e.name + " "); }))
        << followed;
  }
}

TEST(HonestLearning, DadFromTrainingStartsScoresEachIterationFromStartsNoTargetUsed) {
  LearnContext c = recordings_context();
  c.demos.resize(3);
  c.regressor = "knn";
  c.features = "state+clock+start_state@dice+retry/position";
  const int episodes = 4;
  const auto learned = LearnerRegistry::global()
                           .create("dad", {"starts=training", "episodes=" + std::to_string(episodes), "windows=1",
                                           "iterations=1", "keep_best=false", "corrector=track", "tracker_probes=1",
                                           "tracker_robust=1", "tracker_variants=false", "tracker_refine=0"})
                           ->learn(c);
  const auto targets = static_cast<std::size_t>(std::stoul(learned.model->record.at("dad_targets")));
  ASSERT_GT(targets, 0u);
  // As many starts as targets, from the training stream after the targets' own.
  std::vector<Episode> fresh(targets);
  for (std::size_t i = 0; i < targets; ++i) {
    fresh[i].seed = training_start_seed(c.seed, static_cast<std::uint64_t>(episodes) + i);
    fresh[i].states = {random_start_state(c.world, fresh[i].seed)};
  }
  const Tracking t = track_demos([&] { return std::make_unique<ModelPolicy>(learned.model); }, fresh, c.world, 2);
  ASSERT_EQ(learned.curve.size(), 2u);  // the first fit, then the one iteration kept (keep_best=false)
  EXPECT_EQ(learned.curve[1].realistic_success_rate, t.stats.realistic_success.value);
  // Scored from bare starts, not along a target: nothing to deviate from but the start itself,
  // as the world holds it (single precision).
  EXPECT_LT(learned.curve[1].deviation, 1e-5);
  // The starts named are those after the targets' own (training starts 0 to episodes - 1).
  EXPECT_EQ(learned.model->record.at("dad_scored_on"), "training starts 4 to " + std::to_string(3 + targets) +
                                                           ", which no target used (realistic success)");
}

TEST(HonestLearning, ADadCheckpointThatScoredOnItsTargetsStartsIsNotResumed) {
  LearnContext c = recordings_context();
  c.demos.resize(3);
  c.regressor = "knn";
  c.features = "state+clock+start_state@dice+retry/position";
  c.checkpoint_dir = test::scratch_path("dicestack_dad_scored_on");
  fs::remove_all(c.checkpoint_dir);
  const std::vector<std::string> options{"starts=training", "episodes=2", "windows=1", "iterations=1", "corrector=track",
                                         "tracker_probes=1", "tracker_robust=1", "tracker_variants=false", "tracker_refine=0"};
  LearnerRegistry::global().create("dad", options)->learn(c);
  const auto path = c.checkpoint_dir / "dad.json";
  nlohmann::json state;
  std::ifstream(path) >> state;
  ASSERT_EQ(state["run"]["scored_on"], "training starts no target used");
  state["run"].erase("scored_on");  // as written before DaD scored on fresh starts
  { std::ofstream(path) << state.dump(); }
  c.resume = true;
  const std::string refused = test::error_of([&] { LearnerRegistry::global().create("dad", options)->learn(c); });
  EXPECT_THAT(refused, HasSubstr("dad.json: cannot resume a run made with other settings"));
  EXPECT_THAT(refused, HasSubstr("scored_on"));
  fs::remove_all(c.checkpoint_dir);
}

TEST(HonestLearning, TheTrackerFollowsAnotherSetsTrainingEpisodesWhenToldTo) {
  const auto dir = test::scratch_path("dicestack_tracker_demos");
  fs::remove_all(dir);
  DemoSet set;
  set.world = WorldConfig{};
  set.episodes = human_six();
  write_demo_set(set, dir);
  LearnContext c = recordings_context();
  c.demos.clear();  // the run's own set holds nothing the tracker could follow
  const std::vector<std::string> options{"expert=tracker", "episodes=2", "successes_only=false", "tracker_probes=1",
                                         "tracker_optimise=false", "tracker_variants=false", "tracker_refine=0"};
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", options)->learn(c); }),
              HasSubstr("no demonstrations to follow"));
  std::vector<std::string> other = options;
  other.push_back("tracker_demos=" + dir.string());
  const auto learned = LearnerRegistry::global().create("dart", other)->learn(c);
  // Its training episodes: five of the six (episode 4 is the split's test episode).
  EXPECT_THAT(learned.model->record.at("tracker_followed"), HasSubstr("probe trials"));
  EXPECT_THAT(learned.model->record.at("tracker_followed"), Not(HasSubstr("episode_0004")));
  other.back() = "tracker_demos=" + (dir / "missing").string();
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", other)->learn(c); }), HasSubstr("missing"));
  fs::remove_all(dir);
}

TEST(HonestLearning, DaggerFromRecordingsBuildsNoHandMadeExpert) {
  const Forbidden no({"mpc", "scripted"});
  const LearnContext c = recordings_context();
  const auto learned = LearnerRegistry::global()
                           .create("dagger", {"expert=tracker", "iterations=1", "rollouts=2", "tracker_probes=0",
                                              "tracker_optimise=false", "tracker_refine=0"})
                           ->learn(c);
  EXPECT_EQ(learned.model->record.at("expert"), "tracker");
  EXPECT_THAT(learned.model->record.at("tracker_followed"), HasSubstr(" (not ranked)")) << "no probes, no ranking";
}

TEST(HonestLearning, ARefinedPathIsNamedWithItsValidationTrialsEvenWhenTheRankingRanNoProbes) {
  const LearnContext c = recordings_context();
  const auto learned = LearnerRegistry::global()
                           .create("dart", {"expert=tracker", "episodes=2", "successes_only=false", "tracker_probes=0",
                                            "tracker_optimise=false", "tracker_refine=1", "tracker_refine_probes=1",
                                            "tracker_paths=0"})
                           ->learn(c);
  const std::string followed = learned.model->record.at("tracker_followed");
  // 4 x 1 fresh starts, each played clean and noisy; the recordings themselves were not ranked.
  EXPECT_THAT(followed, testing::ContainsRegex(" \\(refined\\) \\([0-8] of 8 probe trials\\)")) << followed;
  EXPECT_THAT(followed, HasSubstr(" (not ranked)")) << followed;
}

TEST(HonestLearning, AModelLearnedFromRecordingsActsWithNoExpertAtAll) {
  const LearnContext c = recordings_context();
  const auto learned = LearnerRegistry::global()
                           .create("dart", {"expert=tracker", "episodes=2", "successes_only=false", "tracker_probes=0",
                                            "tracker_optimise=false", "tracker_refine=0"})
                           ->learn(c);
  const fs::path path = test::scratch_path("dicestack_tracker_model.dsm");
  save_model(*learned.model, path);
  auto model = std::make_shared<const Model>(load_model(path));
  fs::remove(path);
  const Forbidden none({"mpc", "scripted", "tracker"});
  const EvalStats s = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, test::short_world(), test::eval_request(3, 0, 2));
  EXPECT_EQ(s.episodes, 3);
}

TEST(HonestLearning, TheTrackerNeedsDemonstrations) {
  LearnContext c = recordings_context();
  c.demos.clear();
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", {"expert=tracker"})->learn(c); }),
              HasSubstr("expert tracker: no demonstrations to follow"));
}

}  // namespace
}  // namespace dicestack
