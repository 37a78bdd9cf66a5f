// Learner specs ("dart:expert=tracker:episodes=10"): options parsed and checked, the default
// feature map and retries they imply, and the tracker a learner's options make.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/learner.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

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

// In joint torques the tracker follows the path it ranks first without refining it, so it ranks
// from more probe starts; what is given stays as given.
TEST(LearnerSpec, ATrackerInJointTorquesDoesNotRefineAndRanksFromMoreStarts) {
  const std::string map = "state+links+clock+start_state@dice+retry/osc";
  const TrackerConfig by_default = learner_tracker_config(*LearnerRegistry::global().create("dart", {"expert=tracker"}), map);
  EXPECT_EQ(by_default.refine, 0);
  EXPECT_EQ(by_default.probes, 32);
  const TrackerConfig as_option = learner_tracker_config(*LearnerRegistry::global().create("dart", {"expert=tracker", "tracker_probes=32"}), map);
  EXPECT_EQ(by_default.finalist_probes, as_option.finalist_probes) << "the default is the option's value, finalists and all";
  EXPECT_EQ(by_default.controller, ActionKind::joint_torque);
  const TrackerConfig given = learner_tracker_config(
      *LearnerRegistry::global().create("dart", {"expert=tracker", "tracker_probes=8", "tracker_refine=3"}), map);
  EXPECT_EQ(given.probes, 8);
  EXPECT_EQ(given.refine, 3);
  EXPECT_EQ(learner_tracker_config(*LearnerRegistry::global().create("dart", {"expert=tracker"}), "state+clock+start_state@dice+retry/position").probes,
            tracker_preset("distill").probes)
      << "in the cup's actions, the preset's";
}

}  // namespace
}  // namespace dicestack
