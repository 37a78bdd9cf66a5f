// Learners' checkpoints: only our own older data folders are removed, edited states are refused
// naming the field, older versions resume, and regressor settings compare as parsed values.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/learner.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using test::small_context;

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
  EXPECT_EQ(saved.at("version"), 5);
  c.resume = true;
  auto resume_with = [&](const nlohmann::json& state, const std::vector<std::string>& more = {}) {
    { std::ofstream(path) << state.dump(); }
    std::vector<std::string> given = options;
    given.insert(given.end(), more.begin(), more.end());
    return test::error_of([&] { LearnerRegistry::global().create("dagger", given)->learn(c); });
  };
  auto edited = [&](const std::string& pointer, const nlohmann::json& value) {
    nlohmann::json j = saved;
    j[nlohmann::json::json_pointer(pointer)] = value;
    return resume_with(j);
  };
  using ::testing::HasSubstr;
  using ::testing::Not;
  EXPECT_THAT(edited("/version", 6), HasSubstr("dagger.json: format version 6 is newer than this dicestack reads (5)"));
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
  // tracker_paths=-1 is saved as what this run's map made of it (3); a checkpoint of version 4
  // saved "-1" and is resolved with its own map when read; 3 matches, 1 does not.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_paths"], "3");
  tracked["run"]["learner_options"]["tracker_paths"] = "3";
  EXPECT_THAT(resume_with(tracked), Not(HasSubstr("tracker_paths")));
  nlohmann::json v4 = tracked;
  v4["version"] = 4;
  v4["run"]["learner_options"]["tracker_paths"] = "-1";
  EXPECT_THAT(resume_with(v4), Not(HasSubstr("tracker_paths")));
  tracked["run"]["learner_options"]["tracker_paths"] = "1";
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_paths \"1\" in the checkpoint, \"3\" in this run"));
  // Written before tracker_shrink existed, when the tracker never narrowed a path.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_shrink"], "5");
  tracked["run"]["learner_options"]["tracker_paths"] = "-1";
  tracked["run"]["learner_options"].erase("tracker_shrink");
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_shrink \"(absent)\" in the checkpoint, \"5\" in this run"));
  // Written before tracker_refine existed, when the tracker never refined a path.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_refine"], "60");
  tracked["run"]["learner_options"]["tracker_shrink"] = "5";
  tracked["run"]["learner_options"].erase("tracker_refine");
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_refine \"(absent)\" in the checkpoint, \"60\" in this run"));
  // Written before tracker_refine_restarts existed, when a refinement ran once.
  EXPECT_EQ(saved["run"]["learner_options"]["tracker_refine_restarts"], "4");
  tracked["run"]["learner_options"]["tracker_refine"] = "60";
  tracked["run"]["learner_options"].erase("tracker_refine_restarts");
  EXPECT_THAT(resume_with(tracked), HasSubstr("option tracker_refine_restarts \"(absent)\" in the checkpoint, \"4\" in this run"));
  // When neither run refines, the refinement's settings mean nothing.
  nlohmann::json unrefined = tracked;
  unrefined["run"]["learner_options"]["tracker_refine"] = "0";
  EXPECT_THAT(resume_with(unrefined, {"tracker_refine=0"}), Not(HasSubstr("tracker_refine")));
  // Written before retry existed: its absence meant no retries, which auto means for this map
  // (state) and is saved as; "false" and "auto" mean the same, "true" does not.
  EXPECT_EQ(saved["run"]["learner_options"]["retry"], "false");
  nlohmann::json retried = saved;
  retried["run"]["learner_options"].erase("retry");
  EXPECT_EQ(resume_with(retried), "");
  retried["run"]["learner_options"]["retry"] = "auto";
  EXPECT_EQ(resume_with(retried), "");
  retried["run"]["learner_options"]["retry"] = "true";
  EXPECT_THAT(resume_with(retried), HasSubstr("option retry \"true\" in the checkpoint, \"false\" in this run"));
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
