#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/cupdice_import.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
namespace si = state_index;
const fs::path kCupdice = fs::path(DICESTACK_SOURCE_DIR) / "data" / "cupdice";

TEST(CupdiceImport, ImportsAll68Recordings) {
  const DemoSet set = import_cupdice(kCupdice, WorldConfig{});
  ASSERT_EQ(set.episodes.size(), 68u);
  std::size_t frames = 0, stacked = 0;
  for (const auto& e : set.episodes) {
    frames += e.size();
    stacked += e.outcome.stacked;
    EXPECT_EQ(e.outcome.dice_in_cup, 3) << e.origin;
  }
  // 478 final rows, and 17,603 legacy rows less the first of each of 65 files.
  EXPECT_EQ(frames, 478u + 17603u - 65u);
  EXPECT_EQ(set.episodes[0].origin, "cupdice final/imitate_0.csv");
  EXPECT_EQ(set.episodes[3].origin, "cupdice legacy/imitate_0.csv");
  EXPECT_EQ(set.episodes[13].origin, "cupdice legacy/imitate_10.csv");  // natural order
  // All three final-layout recordings end in a stack, as their README says.
  for (std::size_t i = 0; i < 3; ++i) EXPECT_TRUE(set.episodes[i].outcome.stacked) << set.episodes[i].origin;
  EXPECT_GE(stacked, 40u);
}

// Format v2: the recording's last row is the final state; rewards are DiceEnv's for the
// recorded states; a recording ends in success (terminated) or was stopped (truncated).
TEST(CupdiceImport, RecordingsCarryTheirFinalStateRewardsAndEnd) {
  const WorldConfig w;
  const State goal = goal_state(w);
  for (const char* file : {"final/imitate_0.csv", "legacy/imitate_3.csv"}) {
    const Episode e = import_cupdice_file(kCupdice / file, w);
    ASSERT_TRUE(e.has_transitions()) << file;
    ASSERT_EQ(e.rewards.size(), e.size());
    EXPECT_EQ(e.rewards[0], step_reward(e.states[1], 1, w, goal));
    EXPECT_EQ(e.rewards.back(), step_reward(*e.final_state, static_cast<int>(e.size()), w, goal));
    EXPECT_EQ(e.terminated, e.outcome.realistic_success());
    EXPECT_NE(e.terminated, e.truncated);
    EXPECT_NO_THROW(check_episode(e));
  }
  // Final layout: the last row, its cup velocity including the last action.
  const Episode f = import_cupdice_file(kCupdice / "final" / "imitate_0.csv", w);
  EXPECT_EQ((*f.final_state)[si::kCupX], f.states.back()[si::kCupX]);
  EXPECT_EQ((*f.final_state)[si::kCupVx], f.states.back()[si::kCupVx] + f.actions.back()[0]);
}

TEST(CupdiceImport, FinalLayoutConversion) {
  const Episode e = import_cupdice_file(kCupdice / "final" / "imitate_0.csv", WorldConfig{});
  const State& s0 = e.states[0];
  // Body origin (900, 526.67) px at angle pi is the centre of mass (450, 263.33) px.
  EXPECT_NEAR(s0[si::kCupX], 4.5, 1e-9);
  EXPECT_NEAR(s0[si::kCupY], 1.9 + 2.2 / 3.0, 1e-9);
  EXPECT_NEAR(s0[si::kCupAngle], std::numbers::pi, 1e-12);
  EXPECT_NEAR(s0[si::die(1)], 4.51, 1e-12);
  // The recorded cup velocity already contains the action: before it the cup is at rest.
  EXPECT_NEAR(s0[si::kCupVx], 0.0, 1e-5);
  EXPECT_NEAR(s0[si::kCupVy], 0.0, 1e-5);
  // Row 2's recorded velocity is before-action velocity plus the action, in px/s.
  std::ifstream in(kCupdice / "final" / "imitate_0.csv");
  std::string line;
  for (int i = 0; i < 3; ++i) std::getline(in, line);
  std::vector<double> row;
  std::stringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) row.push_back(std::stod(f));
  EXPECT_NEAR(e.states[2][si::kCupVy] + e.actions[2][1], row[22] / 100.0, 1e-12);
  EXPECT_NEAR(e.actions[2][0], row[24] / 100.0, 1e-12);
}

TEST(CupdiceImport, LegacyLayoutConversion) {
  const WorldConfig c;
  const Episode e = import_cupdice_file(kCupdice / "legacy" / "imitate_3.csv", c);
  // The state before action t is row t-1; its cup velocity is the previous command plus one
  // step of gravity, and the action is what reaches this step's command.
  std::ifstream in(kCupdice / "legacy" / "imitate_3.csv");
  std::vector<std::vector<double>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<double> row;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) row.push_back(std::stod(f));
    rows.push_back(row);
  }
  ASSERT_EQ(e.size(), rows.size() - 1);
  for (std::size_t t : {1u, 10u, 50u}) {
    EXPECT_NEAR(e.states[t - 1][si::die(0)], rows[t - 1][3] / 100.0, 1e-12);
    EXPECT_NEAR(e.states[t - 1][si::kCupVy], rows[t - 1][22] / 100.0 - 4.0 / 30.0, 1e-12);
    EXPECT_NEAR(e.states[t - 1][si::kCupVy] + e.actions[t - 1][1], rows[t][22] / 100.0, 1e-12);
  }
}

TEST(CupdiceImport, ReplayedActionsMoveTheCupAsRecorded) {
  // Before the cup meets the dice, replaying the converted actions in our world reproduces the
  // recorded cup velocities: units, centre of mass and action timing agree. Positions differ
  // by Chipmunk's integration order (it moves bodies before adding gravity in a substep: a
  // hovering cup drops 1.8 mm per step there, 2.7 mm in Box2D).
  const WorldConfig c;
  const Episode e = import_cupdice_file(kCupdice / "final" / "imitate_0.csv", c);
  State start = e.states[0];
  World w(c, start);
  for (std::size_t t = 0; t < 3; ++t) {
    w.step(e.actions[t]);
    const State s = w.state();
    EXPECT_NEAR(s[si::kCupVx], e.states[t + 1][si::kCupVx], 1e-3) << "step " << t + 1;
    EXPECT_NEAR(s[si::kCupVy], e.states[t + 1][si::kCupVy], 1e-3) << "step " << t + 1;
    EXPECT_NEAR(s[si::kCupX], e.states[t + 1][si::kCupX], 1e-3) << "step " << t + 1;
    EXPECT_NEAR(s[si::kCupY], e.states[t + 1][si::kCupY], 3e-3 * static_cast<double>(t + 1)) << "step " << t + 1;
  }
}

TEST(CupdiceImport, MalformedRecordingsAreRejected) {
  const fs::path dir = test::scratch_path("dicestack_cupdice_bad");
  fs::create_directories(dir);
  std::ofstream(dir / "short.csv") << "1,2,3\n";
  EXPECT_THAT(test::error_of([&] { import_cupdice_file(dir / "short.csv", WorldConfig{}); }),
              ::testing::HasSubstr("short.csv:1: 3 columns; an original recording has 27"));
  std::ifstream src(kCupdice / "final" / "imitate_2.csv");
  std::string first;
  std::getline(src, first);
  std::ofstream(dir / "nan.csv") << first << "\n" << "nan" << first.substr(first.find(',')) << "\n";
  EXPECT_THAT(test::error_of([&] { import_cupdice_file(dir / "nan.csv", WorldConfig{}); }),
              ::testing::HasSubstr("nan.csv:2: column 1 is not finite"));
  EXPECT_THROW(import_cupdice(dir / "nothing-here", WorldConfig{}), InputError);
  fs::remove_all(dir);
}

TEST(CupdiceImport, ARecordingThatCannotBeReadIsNamedWithTheSystemsReason) {
  const fs::path dir = test::scratch_path("dicestack_cupdice_unreadable");
  fs::remove_all(dir);
  fs::create_directories(dir / "folder.csv");
  EXPECT_EQ(test::error_of([&] { import_cupdice_file(dir / "missing.csv", WorldConfig{}); }),
            (dir / "missing.csv").string() + ": cannot open for reading: No such file or directory");
  EXPECT_EQ(test::error_of([&] { import_cupdice_file(dir / "folder.csv", WorldConfig{}); }),
            (dir / "folder.csv").string() + ": read failed: Is a directory");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dicestack
