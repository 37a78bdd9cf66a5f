// An arm's demonstrations: its links and joint torques kept by the folder format (version 4,
// version 5 with the torques' perturbation),
// robomimic and Minari; a cup set's bytes unchanged; bad arm files refused naming the place.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/perturbation.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/interop/interop.hpp>
#include <dicestack/learners/demonstrator.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/interop.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::expect_same;
using test::scratch;
using test::through_folder;

// Three short episodes of the scripted expert with the arm holding the cup.
DemoSet arm_set() {
  DemoSet set;
  set.world.embodiment = Embodiment::arm;
  set.world.episode.max_steps = 30;
  set.description = "the arm";
  set.episodes = record_expert("scripted", {}, set.world, test::record_request(3, 5, 1));
  for (std::size_t i = 0; i < set.episodes.size(); ++i) set.episodes[i].name = "episode_000" + std::to_string(i);
  return set;
}

std::string text_of(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(ArmSets, ARolloutOnTheArmKeepsItsLinksJointTorquesAndFinalLinks) {
  const DemoSet set = arm_set();
  for (const Episode& e : set.episodes) {
    ASSERT_EQ(e.links.size(), e.size());
    ASSERT_EQ(e.joint_torques.size(), e.size());
    ASSERT_TRUE(e.final_links.has_value());
    bool held = false;  // the cup controller holds the cup up against gravity
    for (const auto& tau : e.joint_torques) held = held || tau[0] != 0.0;
    EXPECT_TRUE(held);
  }
}

TEST(ArmSets, TheFolderKeepsThemAsVersionFourAndACupSetStaysVersionTwo) {
  const DemoSet set = arm_set();
  const fs::path dir = scratch("arm_folder");
  write_demo_set(set, dir);
  const auto meta = nlohmann::json::parse(text_of(dir / "meta.json"));
  EXPECT_EQ(meta["version"], 4);
  EXPECT_TRUE(meta["episodes"][0]["final_links"].is_object());
  EXPECT_TRUE(meta["units"].contains("joint_torques"));
  const std::string csv = text_of(dir / "episode_0000.csv");
  EXPECT_THAT(csv.substr(0, csv.find('\n')), HasSubstr(",reward,link0_angle,link1_angle,link2_angle,link0_rate,link1_rate,"
                                                       "link2_rate,joint0_torque,joint1_torque,joint2_torque,joint3_torque"));
  const DemoSet back = read_demo_set(dir);
  expect_same(set, back);

  DemoSet cup = test::small_set();
  const fs::path cup_dir = scratch("cup_folder");
  write_demo_set(cup, cup_dir);
  EXPECT_EQ(nlohmann::json::parse(text_of(cup_dir / "meta.json"))["version"], 2);
  EXPECT_FALSE(nlohmann::json::parse(text_of(cup_dir / "meta.json"))["units"].contains("joint_torques"));
}

TEST(ArmSets, AnArmsTorqueDrawsAreVersionFiveAndAVersionFourSetCannotHoldThem) {
  DemoSet set;
  set.world.embodiment = Embodiment::arm;
  set.world.episode.max_steps = 20;
  RecordRequest request = test::record_request(2, 5, 1);
  request.perturbation = perturbation_factor("action_noise", "medium");
  request.perturbation.action_delay = 2;
  ExpertConfig torques;
  torques.controller = ActionKind::joint_torque;
  set.episodes = record_expert("scripted", torques, set.world, request);
  for (std::size_t i = 0; i < set.episodes.size(); ++i) set.episodes[i].name = "episode_000" + std::to_string(i);
  const fs::path dir = scratch("arm_torque_draws");
  write_demo_set(set, dir);
  auto meta = nlohmann::json::parse(text_of(dir / "meta.json"));
  EXPECT_EQ(meta["version"], 5);
  const auto& drawn = meta["episodes"][0]["perturbation"];
  EXPECT_EQ(drawn["joint_torque_noise_std"][0], 0.05 * set.world.arm.torque_limit[0]);
  EXPECT_EQ(drawn["action_delay"], 2);
  expect_same(set, read_demo_set(dir));
  EXPECT_EQ(set.episodes[0].actions[0].kind(), ActionKind::joint_torque) << "the torques as chosen";

  // Perturbed in the cup's actions, the arm's set stays version 4.
  DemoSet cup_actions = set;
  cup_actions.episodes = record_expert("scripted", {}, set.world, request);
  for (std::size_t i = 0; i < cup_actions.episodes.size(); ++i) cup_actions.episodes[i].name = "episode_000" + std::to_string(i);
  const fs::path cup_dir = scratch("arm_cup_draws");
  write_demo_set(cup_actions, cup_dir);
  EXPECT_EQ(nlohmann::json::parse(text_of(cup_dir / "meta.json"))["version"], 4);

  meta["version"] = 4;
  write_text(dir / "meta.json", meta.dump());
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }),
              HasSubstr("has the joint torques' bias or noise, which format version 4 does not have (version 5 added them)"));
}

TEST(ArmSets, RobomimicAndMinariCarryTheLinksAndJointTorques) {
  const DemoSet set = through_folder(arm_set(), "arm_through");
  const fs::path file = scratch("arm.hdf5"), dir = scratch("arm_minari");
  export_robomimic(set, file);
  expect_same(set, import_robomimic(file));
  export_minari(set, dir, "dicestack/arm-v0");
  expect_same(set, import_minari(dir));

  // robosuite's joint observations: each joint's angle relative to the body before it.
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t ds = H5Dopen2(f, "data/demo_0/obs/robot0_joint_pos", H5P_DEFAULT);
  ASSERT_GE(ds, 0);
  std::vector<double> q(4 * set.episodes[0].size());
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, q.data());
  H5Dclose(ds);
  H5Fclose(f);
  const auto& a = set.episodes[0].links[0].angles;
  EXPECT_DOUBLE_EQ(q[1], a[1] - a[0]);
  EXPECT_DOUBLE_EQ(q[3], set.episodes[0].states[0][state_index::kCupAngle] - a[2]);
}

TEST(ArmSets, AnEpisodeInJointTorquesKeepsThemAsItsActions) {
  DemoSet set;
  set.world.embodiment = Embodiment::arm;
  set.world.episode.max_steps = 20;
  ExpertConfig torques;
  torques.controller = ActionKind::joint_torque;
  set.episodes = record_expert("scripted", torques, set.world, test::record_request(2, 9, 1));
  ASSERT_EQ(set.episodes[0].actions.front().kind(), ActionKind::joint_torque);
  for (std::size_t i = 0; i < set.episodes.size(); ++i) set.episodes[i].name = "episode_000" + std::to_string(i);
  const fs::path dir = scratch("arm_torques");
  write_demo_set(set, dir);
  const std::string csv = text_of(dir / "episode_0000.csv");
  EXPECT_THAT(csv.substr(0, csv.find('\n')), HasSubstr(",cup_w,joint0_action,joint1_action,joint2_action,joint3_action,source,"));
  expect_same(set, read_demo_set(dir));
  // The exports' action space is the cup's.
  EXPECT_THAT(test::error_of([&] { export_robomimic(read_demo_set(dir), scratch("arm_torques.hdf5")); }),
              HasSubstr("episode episode_0000 acts in joint torques; the export carries the cup's actions"));
  EXPECT_FALSE(fs::exists(scratch("arm_torques.hdf5")));
  // The tracker follows recordings of the cup's actions, and a set holds one kind of action.
  EXPECT_THAT(test::error_of([&] { make_recordings(set.episodes, set.world, tracker_preset("plain"), 0, 1, local_cluster()); }),
              HasSubstr("recording \"episode_0000\" acts in joint torques"));
  DemoSet mixed = set;
  mixed.episodes.push_back(arm_set().episodes[0]);
  EXPECT_THAT(test::error_of([&] { write_demo_set(mixed, scratch("arm_mixed")); }), HasSubstr("a set holds one kind"));
  // An arm's files in a set whose world has no arm.
  auto meta = nlohmann::json::parse(text_of(dir / "meta.json"));
  meta["world"]["embodiment"] = "cup";
  write_text(dir / "meta.json", meta.dump(2));
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("the set's world has no arm"));
}

TEST(ArmSets, BadArmFilesAreRefusedNamingThePlace) {
  const DemoSet set = arm_set();
  // The arm's readings belong to an arm's world.
  DemoSet floating = set;
  floating.world.embodiment = Embodiment::cup;
  EXPECT_THAT(test::error_of([&] { write_demo_set(floating, scratch("arm_floating")); }), HasSubstr("the set's world has no arm"));

  const fs::path dir = scratch("arm_bad");
  auto fresh = [&] {
    fs::remove_all(dir);
    write_demo_set(set, dir);
  };
  // Torques known in one row and not in another.
  fresh();
  std::string csv = text_of(dir / "episode_0001.csv");
  const auto third = csv.find('\n', csv.find('\n', csv.find('\n') + 1) + 1);  // the end of line 3
  const auto cut = csv.rfind(',', csv.rfind(',', csv.rfind(',', csv.rfind(',', third - 1) - 1) - 1) - 1);
  csv.replace(cut, third - cut, ",,,,");
  write_text(dir / "episode_0001.csv", csv);
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }),
              HasSubstr("episode_0001.csv:3: the joint torques are empty but line 2's are numbers"));
  // An arm's file under a meta.json of an older version.
  fresh();
  std::string meta = text_of(dir / "meta.json");
  meta.replace(meta.find("\"version\": 4"), 12, "\"version\": 3");
  write_text(dir / "meta.json", meta);
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("with the arm's links and joint torques), but meta.json says version 3"));
  // Final links that are not three angles and three rates.
  fresh();
  auto j = nlohmann::json::parse(text_of(dir / "meta.json"));
  j["episodes"][2]["final_links"]["rates"] = {1.0, 2.0};
  write_text(dir / "meta.json", j.dump(2));
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }),
              HasSubstr("\"final_links\" of episode_0002.csv: \"rates\" must be a list of 3 numbers"));
  // An arm's file whose entry lost its final links.
  fresh();
  j = nlohmann::json::parse(text_of(dir / "meta.json"));
  j["episodes"][0].erase("final_links");
  write_text(dir / "meta.json", j.dump(2));
  EXPECT_THAT(test::error_of([&] { read_demo_set(dir); }), HasSubstr("episode_0000.csv holds an arm's links, but its entry has no"));
  // Joint torques without the arm's links to run them on.
  Episode bare = set.episodes[0];
  bare.links.clear();
  bare.joint_torques.clear();
  bare.final_links.reset();
  for (Action& a : bare.actions) a = Action::torques({1.0, 2.0, 3.0, 4.0});
  DemoSet lone = set;
  lone.episodes = {bare};
  EXPECT_THAT(test::error_of([&] { write_demo_set(lone, scratch("arm_lone")); }), HasSubstr("acts in joint torques, which command an arm, and has no arm link readings"));
}

}  // namespace
}  // namespace dicestack
