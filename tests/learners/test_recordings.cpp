// Learning from recordings alone: the tracker as the expert of DART and DAgger, with
// the hand-made experts impossible to build, and a model that then acts on its own.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <filesystem>
#include <set>
#include <unistd.h>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/requests.hpp>
#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

// Six of the paper's human recordings (made in Chipmunk, imported once into the cache).
const std::vector<Episode>& human_six() {
  static const std::vector<Episode> six = [] {
    auto all = read_demo_set(human_demo_set(WorldConfig{})).episodes;
    all.resize(6);
    return all;
  }();
  return six;
}

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
                                            "tracker_optimise=false"})
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
  const std::vector<std::string> tracker{"tracker_probes=1", "tracker_robust=1", "tracker_variants=false"};
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
                                         "tracker_optimise=false", "tracker_variants=false"};
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
                                              "tracker_optimise=false"})
                           ->learn(c);
  EXPECT_EQ(learned.model->record.at("expert"), "tracker");
  EXPECT_THAT(learned.model->record.at("tracker_followed"), HasSubstr(" (not ranked)")) << "no probes, no ranking";
}

TEST(HonestLearning, AModelLearnedFromRecordingsActsWithNoExpertAtAll) {
  const LearnContext c = recordings_context();
  const auto learned = LearnerRegistry::global()
                           .create("dart", {"expert=tracker", "episodes=2", "successes_only=false", "tracker_probes=0",
                                            "tracker_optimise=false"})
                           ->learn(c);
  const fs::path path = test::scratch_path("dicestack_tracker_model.dsm");
  save_model(*learned.model, path);
  auto model = std::make_shared<const Model>(load_model(path));
  fs::remove(path);
  const Forbidden none({"mpc", "scripted", "tracker"});
  const EvalStats s = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, test::short_world(), test::eval_request(3, 0, 2));
  EXPECT_EQ(s.episodes, 3);
}

TEST(Recordings, PickedSubsetsAreSeededAndAllMeansAll) {
  const auto names = [](const std::vector<Episode>& es) {
    std::vector<std::string> out;
    for (const auto& e : es) out.push_back(e.name);
    return out;
  };
  EXPECT_EQ(names(pick_recordings(human_six(), 0, 1)), names(human_six()));
  EXPECT_EQ(names(pick_recordings(human_six(), 6, 1)), names(human_six()));
  const auto three = pick_recordings(human_six(), 3, 1);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(names(pick_recordings(human_six(), 3, 1)), names(three));
  std::set<std::string> distinct;
  for (const auto& n : names(three)) distinct.insert(n);
  EXPECT_EQ(distinct.size(), 3u);
  bool another = false;  // some other seed draws another subset
  for (std::uint64_t seed = 2; seed < 10 && !another; ++seed) another = names(pick_recordings(human_six(), 3, seed)) != names(three);
  EXPECT_TRUE(another);
}

TEST(HonestLearning, TheTrackerNeedsDemonstrations) {
  LearnContext c = recordings_context();
  c.demos.clear();
  EXPECT_THAT(test::error_of([&] { LearnerRegistry::global().create("dart", {"expert=tracker"})->learn(c); }),
              HasSubstr("expert tracker: no demonstrations to follow"));
}

TEST(Tracker, RecordingThroughItDoesNotDependOnThreadsAndNamesItsExpert) {
  TrackerConfig t;
  t.probes = 1;
  t.optimise = false;
  ExpertConfig config;
  config.recordings = make_recordings(human_six(), WorldConfig{}, t, 0, 2);
  const auto one = record_expert("tracker", config, WorldConfig{}, test::record_request(2, 4, 1));
  const auto two = record_expert("tracker", config, WorldConfig{}, test::record_request(2, 4, 2));
  ASSERT_EQ(one.size(), 2u);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].states, two[i].states);
    EXPECT_EQ(one[i].origin, "expert tracker");
  }
}

TEST(LearnerSpec, ParsesOptionsAndRefusesUnknownOnes) {
  const LearnerSpec s = parse_learner_spec("dart:expert=tracker:episodes=10");
  EXPECT_EQ(s.name, "dart");
  EXPECT_EQ(s.options, (std::vector<std::string>{"expert=tracker", "episodes=10"}));
  EXPECT_EQ(parse_learner_spec("bc").options.size(), 0u);
  EXPECT_THAT(test::error_of([] { parse_learner_spec("dart:expert=oracle"); }), HasSubstr("learner \"dart:expert=oracle\""));
  EXPECT_THROW(parse_learner_spec("dartt"), ConfigError);
  EXPECT_THROW(parse_learner_spec("dart:noise"), ConfigError);
}

TEST(LearnerSpec, DartLabelledByTheTrackerReadsItsMapAnsweringPosesFromTheDice) {
  EXPECT_EQ(default_features("bc"), "state");
  EXPECT_EQ(default_features("dart"), "state+clock+start_state");
  EXPECT_EQ(default_features("dart", {"expert=mpc"}), "state+clock+start_state");
  EXPECT_EQ(default_features("dart", {"expert=tracker", "episodes=10"}), "state+clock+start_state@dice+retry/position");
  EXPECT_EQ(feature_map(default_features("dart", {"expert=tracker"})).target(), ActionTarget::position);
  EXPECT_THROW(default_features("dart", {"expert=oracle"}), ConfigError);
}

TEST(LearnerSpec, TheExpertTriesAgainWithARetryMapUnlessToldOtherwise) {
  // retry=auto follows the map: its clock and start restart with each attempt, as the expert's
  // choices then do.
  EXPECT_TRUE(expert_retries("auto", "state+clock+start_state@dice+retry/position"));
  EXPECT_TRUE(expert_retries("auto", "state+clock+start_state+retry"));
  EXPECT_FALSE(expert_retries("auto", "state+clock+start_state@dice/position"));
  EXPECT_FALSE(expert_retries("false", "state+clock+start_state+retry"));
  EXPECT_TRUE(expert_retries("true", "state+clock+start_state"));
  EXPECT_THROW(parse_learner_spec("dart:retry=maybe"), ConfigError);
  EXPECT_NO_THROW(parse_learner_spec("dagger:expert=mpc:retry=true"));
}

TEST(LearnerSpec, TheLearnersTrackerIsThePresetWithTheOptionsGivenOnTop) {
  // One set of defaults: every tracker_* option's default is the distill preset's setting.
  const TrackerConfig distill = tracker_preset("distill");
  const auto learner = LearnerRegistry::global().create("dart", {"expert=tracker"});
  const TrackerConfig by_default = learner_tracker_config(*learner, "state+clock+start_state@dice+retry/position");
  EXPECT_EQ(by_default.smooth, distill.smooth);
  EXPECT_EQ(by_default.robust, distill.robust);
  EXPECT_EQ(by_default.shrink, distill.shrink);
  EXPECT_EQ(by_default.variants, distill.variants);
  EXPECT_EQ(by_default.paths, 1) << "one recording for a /position map";
  const auto settings_equal = [](const TrackerConfig& x, const TrackerConfig& y) {
    return x.probes == y.probes && x.optimise == y.optimise && x.smooth == y.smooth && x.rescue == y.rescue &&
           x.robust == y.robust && x.robust_noise == y.robust_noise && x.robust_warp == y.robust_warp &&
           x.keep_extremes == y.keep_extremes && x.shrink == y.shrink && x.variants == y.variants &&
           x.finalist_probes == y.finalist_probes;
  };
  for (const auto& spec : LearnerRegistry::global().info("dart").params) {
    const std::string setting = spec.name.starts_with("tracker_") ? spec.name.substr(8) : "";
    const auto& names = tracker_setting_names();
    if (setting.empty() || setting == "paths" || std::find(names.begin(), names.end(), setting) == names.end()) continue;
    TrackerConfig with_default = distill;
    set_tracker_setting(with_default, setting, spec.default_value);
    EXPECT_TRUE(settings_equal(with_default, distill)) << spec.name << "'s default is not the preset's";
  }
  // Another preset: its settings, the options given on top, the others not the distill defaults.
  const auto plain = LearnerRegistry::global().create("dart", {"expert=tracker", "tracker_preset=plain", "tracker_smooth=2"});
  const TrackerConfig p = learner_tracker_config(*plain, "state+clock+start_state@dice+retry/position");
  EXPECT_EQ(p.smooth, 2.0);
  EXPECT_EQ(p.robust, 0);
  EXPECT_TRUE(p.variants.empty());
  EXPECT_EQ(p.paths, 0) << "plain follows all its recordings";
  EXPECT_THAT(test::error_of([] { parse_learner_spec("dart:tracker_preset=tuned"); }), HasSubstr("plain, distill"));
  // What checkpoints compare and models record: an option not given shows the preset's value, so
  // two runs with the same text ran the same tracker.
  const auto options = [](const Learner& l) {
    std::map<std::string, std::string> out;
    for (const auto& [k, v] : effective_options(l)) out[k] = v;
    return out;
  };
  const auto shown = options(*plain);
  EXPECT_EQ(shown.at("tracker_smooth"), "2") << "given";
  EXPECT_EQ(shown.at("tracker_robust"), "0") << "plain's, not distill's default 5";
  EXPECT_EQ(shown.at("tracker_variants"), "false");
  const auto plain_smooth_4 =
      LearnerRegistry::global().create("dart", {"expert=tracker", "tracker_preset=plain", "tracker_smooth=4"});
  const auto plain_alone = LearnerRegistry::global().create("dart", {"expert=tracker", "tracker_preset=plain"});
  EXPECT_NE(options(*plain_smooth_4).at("tracker_smooth"), options(*plain_alone).at("tracker_smooth"));
  const auto distill_default = LearnerRegistry::global().create("dart", {"expert=tracker"});
  std::map<std::string, std::string> as_text;
  for (const auto& [k, v] : distill_default->params().as_text()) as_text[k] = v;
  EXPECT_EQ(options(*distill_default), as_text) << "the learners' preset: its options' text as before";
}

}  // namespace
}  // namespace dicestack
