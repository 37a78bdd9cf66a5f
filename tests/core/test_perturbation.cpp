#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/perturbation.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

TEST(Perturbation, LevelsGrowAndNoneIsNominal) {
  EXPECT_TRUE(perturbation_level("none").nominal());
  const Perturbation easy = perturbation_level("easy"), medium = perturbation_level("medium"),
                     hard = perturbation_level("hard");
  EXPECT_LT(easy.friction, medium.friction);
  EXPECT_LT(medium.friction, hard.friction);
  EXPECT_LT(easy.action_delay, hard.action_delay);
  EXPECT_GT(hard.action_bias, 0.0);
  const WorldConfig w;
  for (const auto& level : perturbation_levels()) EXPECT_NO_THROW(validate(perturbation_level(level), w)) << level;
}

TEST(Perturbation, OneFactorLeavesTheOthersNominal) {
  for (const auto& f : perturbation_factors()) {
    const Perturbation p = perturbation_factor(f, "medium");
    EXPECT_FALSE(p.nominal()) << f;
    EXPECT_TRUE(perturbation_factor(f, "none").nominal()) << f;
  }
  const Perturbation p = perturbation_factor("gravity", "hard");
  EXPECT_GT(p.gravity, 0.0);
  EXPECT_EQ(p.friction, 0.0);
  EXPECT_EQ(p.action_delay, 0);
}

TEST(Perturbation, UnknownFactorOrLevelIsRefusedNamingTheChoices) {
  EXPECT_THAT(test::error_of([] { perturbation_factor("wind", "easy"); }), HasSubstr("friction, dice_mass"));
  EXPECT_THAT(test::error_of([] { perturbation_level("extreme"); }), HasSubstr("none, easy, medium, hard"));
  EXPECT_THAT(test::error_of([] { perturbation_factor("friction", "extreme"); }), HasSubstr("\"extreme\""));
}

TEST(Perturbation, InvalidRangesAreRefusedNamingTheField) {
  const WorldConfig w = test::short_world(60);
  Perturbation p;
  p.friction = 1.0;  // a friction coefficient could reach 0 or below
  EXPECT_THAT(test::error_of([&] { validate(p, w); }), HasSubstr("\"friction\""));
  p = {};
  p.dice_mass = -0.1;
  EXPECT_THAT(test::error_of([&] { validate(p, w); }), HasSubstr("\"dice_mass\""));
  p = {};
  p.action_delay = 60;  // the whole episode
  EXPECT_THAT(test::error_of([&] { validate(p, w); }), HasSubstr("\"action_delay\""));
  p = {};
  p.observation_delay = -1;
  EXPECT_THAT(test::error_of([&] { validate(p, w); }), HasSubstr("\"observation_delay\""));
  p = {};
  p.gravity = std::nan("");
  EXPECT_THAT(test::error_of([&] { validate(p, w); }), HasSubstr("\"gravity\""));
}

// The reference page's keys are the file's: each is read, written and refused past its range.
TEST(Perturbation, TheKeyListIsTheFilesKeys) {
  const WorldConfig w;
  const auto written = nlohmann::json::parse(perturbation_to_json(Perturbation{}));
  const auto keys = perturbation_keys();
  EXPECT_EQ(keys.size() + 2, written.size());  // and "format", "version"
  for (const auto& k : keys) {
    EXPECT_TRUE(written.contains(k.name)) << k.name;
    EXPECT_FALSE(k.meaning.empty()) << k.name;
    if (k.type == "boolean") continue;
    nlohmann::json file = written;
    file[k.name] = 1000;
    EXPECT_THAT(test::error_of([&] { perturbation_from_json(file.dump(), "p.json", w); }),
                HasSubstr("field \"" + k.name + "\" must be in [0, "))
        << k.name;
  }
}

TEST(Perturbation, NominalDrawLeavesTheWorldAlone) {
  const WorldConfig w;
  const PerturbationDraw d = draw_perturbation(Perturbation{}, w, 42);
  EXPECT_EQ(to_json(d.world), to_json(w));
  EXPECT_FALSE(d.physics);
  EXPECT_FALSE(d.acts);
}

TEST(Perturbation, DrawsArePureFunctionsOfTheSeed) {
  const WorldConfig w;
  const Perturbation p = perturbation_level("hard");
  const PerturbationDraw a = draw_perturbation(p, w, 7), b = draw_perturbation(p, w, 7), c = draw_perturbation(p, w, 8);
  EXPECT_EQ(to_json(a.world), to_json(b.world));
  EXPECT_EQ(a.action_bias, b.action_bias);
  EXPECT_EQ(a.noise_seed, b.noise_seed);
  EXPECT_NE(a.world.dice.mass, c.world.dice.mass);
  EXPECT_TRUE(a.physics);
  EXPECT_TRUE(a.acts);
  // Within the level's ranges.
  EXPECT_GE(a.world.dice.mass, w.dice.mass * (1 - p.dice_mass));
  EXPECT_LE(a.world.dice.mass, w.dice.mass * (1 + p.dice_mass));
  EXPECT_GT(a.world.dice.friction, 0.0);
  EXPECT_DOUBLE_EQ(a.world.randomization.shift, w.randomization.shift * (1 + p.start_widening));
  EXPECT_NO_THROW(validate(a.world));
}

TEST(Perturbation, StartsTooWideForTheWallsAreRefused) {
  WorldConfig wide;
  wide.randomization.shift = 1.2;  // valid alone; four times it puts the scene through a wall
  ASSERT_NO_THROW(validate(wide));
  Perturbation p;
  p.start_widening = 3.0;
  EXPECT_NO_THROW(validate(p, WorldConfig{}));
  EXPECT_THAT(test::error_of([&] { validate(p, wide); }), HasSubstr("\"start_widening\""));
}

TEST(Perturbation, AFactorsDrawDoesNotDependOnTheOthers) {
  const WorldConfig w;
  const PerturbationDraw alone = draw_perturbation(perturbation_factor("dice_mass", "hard"), w, 3);
  Perturbation both = perturbation_factor("dice_mass", "hard");
  both.friction = 0.5;
  const PerturbationDraw with = draw_perturbation(both, w, 3);
  EXPECT_EQ(alone.world.dice.mass, with.world.dice.mass);
  EXPECT_NE(alone.world.dice.friction, with.world.dice.friction);
}

TEST(Perturbation, JsonRoundTripsAndLoadsByLevelOrFile) {
  const WorldConfig w;
  const Perturbation p = perturbation_level("medium");
  EXPECT_EQ(perturbation_from_json(perturbation_to_json(p), "p.json", w), p);
  EXPECT_EQ(load_perturbation("hard", w), perturbation_level("hard"));
  const auto path = std::filesystem::temp_directory_path() / ("perturb-" + std::to_string(getpid()) + ".json");
  std::ofstream(path) << perturbation_to_json(p);
  EXPECT_EQ(load_perturbation(path.string(), w), p);
  std::filesystem::remove(path);
  EXPECT_THAT(test::error_of([&] { load_perturbation("nowhere.json", w); }), HasSubstr("nowhere.json"));
  // A folder is neither a level nor a readable file: the system says why.
  const auto dir = test::scratch_path("dicestack_perturb_folder");
  std::filesystem::create_directories(dir);
  EXPECT_EQ(test::error_of([&] { load_perturbation(dir.string(), w); }), dir.string() + ": read failed: Is a directory");
  std::filesystem::remove(dir);
}

TEST(Perturbation, BadFilesAreRefusedNamingTheField) {
  const WorldConfig w = test::short_world(60);
  auto error = [&](const std::string& text) { return test::error_of([&] { perturbation_from_json(text, "p.json", w); }); };
  const std::string head = R"({"format": "dicestack-perturbation", "version": 1, )";
  EXPECT_THAT(error(R"({"format": "dicestack-perturbation", "version": 3})"), HasSubstr("format version 3 is newer than this dicestack reads (2)"));
  EXPECT_THAT(error(R"({"format": "dicestack-world", "version": 1})"), HasSubstr("not a perturbation file"));
  EXPECT_THAT(error(head + R"("wind": 0.1})"), HasSubstr("unknown field \"wind\""));
  EXPECT_THAT(error(head + R"("friction": "lots"})"), HasSubstr("\"friction\" must be a number"));
  EXPECT_THAT(error(head + R"("cup_mass": -0.5})"), HasSubstr("\"cup_mass\""));
  EXPECT_THAT(error(head + R"("action_delay": 1.5})"), HasSubstr("\"action_delay\" must be an integer"));
  EXPECT_THAT(error(head + R"("observation_delay": 500})"), HasSubstr("\"observation_delay\""));
  EXPECT_THAT(error("{"), HasSubstr("p.json: not JSON"));
  // Drawn delays are version 2, a boolean, and need a delay to draw up to.
  EXPECT_THAT(error(head + R"("action_delay": 3, "delays_drawn": true})"),
              HasSubstr("field \"delays_drawn\" is format version 2; this file says version 1"));
  const std::string head2 = R"({"format": "dicestack-perturbation", "version": 2, )";
  EXPECT_THAT(error(head2 + R"("action_delay": 3, "delays_drawn": 1})"), HasSubstr("\"delays_drawn\" must be true or false"));
  EXPECT_THAT(error(head2 + R"("delays_drawn": true})"), HasSubstr("\"delays_drawn\" draws each episode's delays"));
}

TEST(Perturbation, VersionOneFilesStillLoad) {
  // A file as dicestack wrote it before drawn delays (format version 1).
  const std::string v1 = R"({"format": "dicestack-perturbation", "version": 1, "friction": 0.3, "action_delay": 3})";
  const Perturbation p = perturbation_from_json(v1, "old.json", WorldConfig{});
  EXPECT_EQ(p.friction, 0.3);
  EXPECT_EQ(p.action_delay, 3);
  EXPECT_FALSE(p.delays_drawn);
}

TEST(Perturbation, DrawnDelaysCoverTheirRangeAndLeaveTheOtherDrawsAlone) {
  const WorldConfig w;
  Perturbation fixed = perturbation_level("medium");
  fixed.action_delay = 3;
  fixed.observation_delay = 2;
  Perturbation drawn = fixed;
  drawn.delays_drawn = true;
  EXPECT_EQ(perturbation_from_json(perturbation_to_json(drawn), "p.json", w), drawn);
  EXPECT_THAT(perturbation_summary(drawn), HasSubstr("delays drawn from 0"));
  std::array<int, 4> action_seen{}, observation_seen{};
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    const PerturbationDraw d = draw_perturbation(drawn, w, seed), f = draw_perturbation(fixed, w, seed);
    ASSERT_GE(d.action_delay, 0);
    ASSERT_LE(d.action_delay, 3);
    ASSERT_GE(d.observation_delay, 0);
    ASSERT_LE(d.observation_delay, 2);
    ++action_seen[static_cast<std::size_t>(d.action_delay)];
    ++observation_seen[static_cast<std::size_t>(d.observation_delay)];
    EXPECT_EQ(draw_perturbation(drawn, w, seed).action_delay, d.action_delay) << "reproducible";
    // Everything else is what the fixed delays' file draws, number for number.
    EXPECT_EQ(to_json(d.world), to_json(f.world)) << seed;
    EXPECT_EQ(d.action_bias, f.action_bias) << seed;
    EXPECT_EQ(d.noise_seed, f.noise_seed) << seed;
    EXPECT_EQ(f.action_delay, 3);
  }
  for (int n : action_seen) EXPECT_GT(n, 20) << "every action delay from 0 to 3 drawn";
  EXPECT_EQ(observation_seen[3], 0);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_GT(observation_seen[k], 30) << k;
}

TEST(Perturbation, JointTorquesGetTheirOwnDrawsAfterTheCupsFromTheTorqueLimits) {
  WorldConfig arm;
  arm.embodiment = Embodiment::arm;
  const Perturbation p = perturbation_factor("action_noise", "medium");
  const PerturbationDraw d = draw_perturbation(p, arm, 7), cup = draw_perturbation(p, WorldConfig{}, 7);
  // The cup's draws are the floating cup's, number for number: the torques' come after them.
  EXPECT_EQ(d.action_bias, cup.action_bias);
  EXPECT_EQ(d.noise_seed, cup.noise_seed);
  for (std::size_t k = 0; k < kJointCount; ++k) {
    EXPECT_DOUBLE_EQ(d.torque_noise[k], 0.05 * arm.arm.torque_limit[k]);
    EXPECT_NE(d.torque_bias[k], 0.0);
    EXPECT_LT(std::abs(d.torque_bias[k]), 5 * 0.015 * arm.arm.torque_limit[k]);
  }
  // Only the record of an episode in joint torques names them, and they read back.
  EXPECT_EQ(draw_to_json(cup).find("joint_torque"), std::string::npos);
  EXPECT_EQ(draw_to_json(d).find("joint_torque"), std::string::npos) << "the arm's episode in the cup's actions";
  const PerturbationDraw back = channel_draw_from_json(draw_to_json(d, ActionKind::joint_torque), "e");
  EXPECT_EQ(back.torque_bias, d.torque_bias);
  EXPECT_EQ(back.torque_noise, d.torque_noise);
  EXPECT_THAT(test::error_of([] { channel_draw_from_json(R"({"joint_torque_noise_std": [1, 2, -3, 4]})", "e"); }),
              HasSubstr("e: its perturbation's \"joint_torque_noise_std\" must be 4 standard deviations >= 0"));
}

TEST(Perturbation, AChannelDelaysJointTorquesBehindZeroTorquesAndNoisesThemInNewtonMetres) {
  PerturbationDraw d;
  d.action_delay = 2;
  d.torque_bias = Action::torques({10.0, 0.0, 0.0, 0.0});
  d.torque_noise = Action::torques({0.0, 0.0, 0.0, 5.0});
  d.noise_seed = 3;
  PerturbedChannel channel(d, ActionKind::joint_torque);
  ASSERT_EQ(channel.pending().size(), 2u);
  EXPECT_EQ(channel.pending().front(), Action::zeros(ActionKind::joint_torque));
  const Action chosen = Action::torques({100.0, 200.0, 300.0, 400.0});
  for (int step = 0; step < 2; ++step) {
    const Action idle = channel.execute(chosen);
    EXPECT_EQ(idle.kind(), ActionKind::joint_torque) << "nothing runs: zero torques, plus the bias";
    EXPECT_EQ(idle[0], 10.0);
    EXPECT_EQ(idle[1], 0.0);
    EXPECT_NE(idle[3], 0.0) << "the wrist's noise";
  }
  const Action late = channel.execute(chosen);
  EXPECT_EQ(late[0], 110.0);
  EXPECT_EQ(late[2], 300.0);
  EXPECT_NEAR(late[3], 400.0, 5 * 5.0);
  ASSERT_EQ(channel.pending().size(), 2u);
  EXPECT_EQ(channel.pending().front(), chosen);
  EXPECT_THAT(test::error_of([&] { channel.execute(Action{0.0, 0.0, 0.0}); }),
              HasSubstr("a choice for the cup controller, where the policy answers joint_torque actions"));
}

}  // namespace
}  // namespace dicestack
