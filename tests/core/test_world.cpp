#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

#include <box2d/box2d.h>

#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using ::testing::HasSubstr;

double dice_kinetic_energy(const State& s, const WorldConfig& c) {
  double e = 0.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i);
    e += 0.5 * c.dice.mass * (s[d + 3] * s[d + 3] + s[d + 4] * s[d + 4]);
  }
  return e;
}

TEST(World, StartStateIsThePapers) {
  const WorldConfig c;
  const State s = World(c).state();
  EXPECT_NEAR(s[si::kCupX], 4.5, 1e-6);
  EXPECT_NEAR(s[si::kCupY], 1.9 + 2.2 / 3.0, 1e-6);
  EXPECT_NEAR(s[si::kCupAngle], std::numbers::pi, 1e-6);
  EXPECT_NEAR(s[si::die(0)], 4.08, 1e-6);
  EXPECT_NEAR(s[si::die(2)], 4.93, 1e-6);
  EXPECT_NEAR(s[si::die(1) + 1], 1.25, 1e-6);
}

TEST(World, StatesOutsideTheWorldAreRefusedNamingTheBody) {
  namespace si = state_index;
  const WorldConfig c;
  const State start = paper_start_state(c);
  EXPECT_NO_THROW(check_state_in_world(start, c, "s"));
  EXPECT_NO_THROW(check_state_in_world(random_start_state(c, 4), c, "s"));
  auto error = [&](std::size_t at, double value) {
    State s = start;
    s[at] = value;
    return test::error_of([&] { check_state_in_world(s, c, "reset state"); });
  };
  EXPECT_THAT(error(si::die(0), 1e9), ::testing::HasSubstr("reset state: die 0 is beyond the walls (x = 1e+09 m"));
  EXPECT_THAT(error(si::kCupX, -3.0), ::testing::HasSubstr("the cup is beyond the walls"));
  EXPECT_THAT(error(si::die(2) + 1, 0.5), ::testing::HasSubstr("die 2 is under the table (y = 0.5 m; its surface is at 1.00 m)"));
  EXPECT_THAT(error(si::die(1) + 1, 1e9), ::testing::HasSubstr("die 1 is above the ceiling"));
  EXPECT_THAT(error(si::die(1), start[si::die(0)] + 0.05), ::testing::AllOf(::testing::HasSubstr("die 0"), ::testing::HasSubstr("die 1"),
                                                                           ::testing::HasSubstr("overlap by")));
  EXPECT_THAT(error(si::kCupAngle, std::nan("")), ::testing::HasSubstr("reset state"));
}

TEST(World, DieFallsWithGravityUntilContact) {
  const WorldConfig c;
  State s = paper_start_state(c);
  s[si::die(0)] = 2.0;  // away from the cup
  s[si::die(0) + 1] = 4.0;
  World w(c, s);
  const double dt = c.physics.control_dt, h = dt / c.physics.substeps;
  double y = 4.0, v = 0.0;
  for (int t = 1; t <= 20; ++t) {
    w.step({0.0, 0.0, 0.0});
    for (int k = 0; k < c.physics.substeps; ++k) {  // Box2D's semi-implicit Euler
      v += -4.0 * h;
      y += v * h;
    }
    const State now = w.state();
    ASSERT_NEAR(now[si::die(0) + 4], -4.0 * dt * t, 1e-4) << "step " << t;
    ASSERT_NEAR(now[si::die(0) + 1], y, 1e-4) << "step " << t;
  }
}

TEST(World, DiceSettleOnTheTableWithoutJitter) {
  const WorldConfig c;
  World w(c);
  for (int t = 0; t < 30; ++t) w.step({0.0, 0.0, 0.0});  // one second
  State s = w.state();
  EXPECT_LT(dice_kinetic_energy(s, c), 1e-3);
  for (int t = 0; t < 30; ++t) w.step({0.0, 0.0, 0.0});
  s = w.state();
  EXPECT_LT(dice_kinetic_energy(s, c), 1e-9);
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    // Resting on the table: centre at table + half size, within Box2D's 0.5 mm slop and the
    // cup wall leaning on die 2.
    EXPECT_NEAR(s[si::die(i) + 1], 1.2, 2e-3) << "die " << i;
  }
}

TEST(World, CupWithoutActionFallsAndRestsOnTheTable) {
  const WorldConfig c;
  World w(c);
  const double y0 = w.state()[si::kCupY];
  for (int t = 0; t < 90; ++t) w.step({0.0, 0.0, 0.0});
  const State s = w.state();
  // The mouth-down rim starts 0.1167 m above the table (rim centre line 1.1667 minus radius).
  const double rim_gap = (c.cup.start_anchor.y + 2.0 * (2.2 / 3.0) - 2.2 - c.cup.radius) - 1.0;  // 0.1167 m
  EXPECT_NEAR(s[si::kCupY], y0 - rim_gap, 1e-3);
  EXPECT_NEAR(s[si::kCupVy], 0.0, 1e-6);
  EXPECT_NEAR(s[si::kCupVx], 0.0, 1e-6);
}

TEST(World, ActionChangesCupVelocityByExactlyItsValue) {
  const WorldConfig c;
  State s = paper_start_state(c);
  s[si::kCupY] = 5.0;  // in free flight, far from everything
  s[si::kCupVx] = 0.37;
  World w(c, s);
  const State before = w.state();
  w.step({1.0, 0.0, 0.0});
  State after = w.state();
  EXPECT_NEAR(after[si::kCupVx] - before[si::kCupVx], 1.0, 1e-6);
  EXPECT_NEAR(after[si::kCupVy] - before[si::kCupVy], -4.0 * c.physics.control_dt, 1e-6);
  w.step({0.0, 0.5, -0.25});
  const State third = w.state();
  EXPECT_NEAR(third[si::kCupVy] - after[si::kCupVy], 0.5 - 4.0 * c.physics.control_dt, 1e-6);
  EXPECT_NEAR(third[si::kCupW] - after[si::kCupW], -0.25, 1e-6);
}

TEST(World, StateRoundTripsExactly) {
  const WorldConfig c;
  World w(c, random_start_state(c, 3));
  for (const auto& a : test::random_actions(c, 4, 40)) w.step(a);
  const State s = w.state();
  World copy(c, s);
  EXPECT_TRUE(test::bit_equal(copy.state(), s));
  copy.set_state(s);
  EXPECT_TRUE(test::bit_equal(copy.state(), s));
}

TEST(World, SameSeedAndActionsGiveBitIdenticalStates) {
  const WorldConfig c;
  const auto actions = test::random_actions(c, 11, 300);
  std::uint64_t hashes[2];
  for (auto& h : hashes) {
    World w(c, random_start_state(c, 5));
    h = hash_state(w.state());
    for (const auto& a : actions) {
      w.step(a);
      h = hash_state(w.state(), h);
    }
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  World other(c, random_start_state(c, 6));
  std::uint64_t h = hash_state(other.state());
  for (const auto& a : actions) {
    other.step(a);
    h = hash_state(other.state(), h);
  }
  EXPECT_NE(h, hashes[0]);
}

// Box2D times its steps for a profile nothing here reads; core/world/src/box2d_timer.cpp stops
// that clock for every caller in the process, Box2D's own steps included.
TEST(World, Box2DsProfileClockIsStopped) {
  const b2Timer timer;
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(timer.GetMilliseconds(), 0.0f);

  b2World world(b2Vec2(0.0f, -9.8f));
  b2BodyDef ground_def;
  b2PolygonShape ground;
  ground.SetAsBox(5.0f, 0.1f);
  world.CreateBody(&ground_def)->CreateFixture(&ground, 0.0f);
  b2PolygonShape box;
  box.SetAsBox(0.05f, 0.05f);
  for (int i = 0; i < 400; ++i) {  // a pile whose steps take well over a millisecond in all
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(-4.0f + 0.2f * static_cast<float>(i % 40), 0.2f + 0.11f * static_cast<float>(i / 40));
    world.CreateBody(&def)->CreateFixture(&box, 1.0f);
  }
  float total = 0.0f;
  for (int i = 0; i < 30; ++i) {
    world.Step(1.0f / 150.0f, 10, 8);
    const b2Profile& p = world.GetProfile();
    total += p.step + p.collide + p.solve + p.solveTOI + p.broadphase;
  }
  EXPECT_EQ(total, 0.0f);
}

TEST(World, PushingIntoSideWallsAndCeilingIsReported) {
  const WorldConfig c;
  World w(c);
  bool touched = false;
  for (int t = 0; t < 60 && !touched; ++t) touched = w.step({t == 0 ? -3.0 : 0.0, 0.1, 0.0});
  EXPECT_TRUE(touched) << "cup pushed left never touched the left wall";
  World up(c);
  touched = false;
  for (int t = 0; t < 90 && !touched; ++t) touched = up.step({0.0, t == 0 ? 6.0 : 0.134, 0.0});
  EXPECT_TRUE(touched) << "cup pushed up never touched the ceiling";
  World still(c);
  for (int t = 0; t < 60; ++t) EXPECT_FALSE(still.step({0.0, 0.0, 0.0}));
}

TEST(World, RejectsNonFiniteStatesAndActions) {
  const WorldConfig c;
  World w(c);
  Action bad{0.0, std::nan(""), 0.0};
  EXPECT_THAT(test::error_of([&] { w.step(bad); }), HasSubstr("action: element 1 is NaN"));
  State s = w.state();
  s[7] = INFINITY;
  EXPECT_THAT(test::error_of([&] { w.set_state(s); }), HasSubstr("world state: element 7 is infinite"));
  EXPECT_THROW(w.set_state(s), InputError);
}

TEST(World, WrongSizedVectorsAreRejected) {
  const std::vector<double> five(5, 0.0);
  EXPECT_THAT(test::error_of([&] { to_state(five, "row 3"); }), HasSubstr("row 3: a state needs 24 values, got 5"));
  EXPECT_THAT(test::error_of([&] { to_action(five, "policy output"); }),
              HasSubstr("policy output: an action needs 3 values, got 5"));
  const std::vector<double> ok{0.1, 0.2, 0.3};
  EXPECT_EQ(to_action(ok, "x")[2], 0.3);
}

TEST(World, RandomStartsDifferAndDoNotOverlap) {
  const WorldConfig c;
  const State a = random_start_state(c, 1), b = random_start_state(c, 2);
  EXPECT_FALSE(test::bit_equal(a, b));
  EXPECT_TRUE(test::bit_equal(a, random_start_state(c, 1)));
  for (std::uint64_t seed = 0; seed < 50; ++seed) EXPECT_FALSE(World(c, random_start_state(c, seed)).has_overlaps());
  WorldConfig none = c;
  none.randomization = {0.0, 0.0, 0.0, 0.0, false};
  EXPECT_TRUE(test::bit_equal(random_start_state(none, 9), paper_start_state(none)));
}

TEST(World, PaperStartsAreThePapersStartAtRestShiftedWholeByAtMostTwoCentimetres) {
  const WorldConfig paper = with_starts(WorldConfig{}, "paper");
  EXPECT_EQ(start_distribution_name(paper), "paper");
  EXPECT_EQ(start_distribution_name(WorldConfig{}), "random");
  EXPECT_EQ(with_starts(WorldConfig{}, "random"), WorldConfig{});
  const State home = paper_start_state(paper);
  double widest = 0.0;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    const State s = random_start_state(paper, seed);
    const double shift = s[state_index::kCupX] - home[state_index::kCupX];
    widest = std::max(widest, std::abs(shift));
    for (std::size_t k = 0; k < kStateDim; ++k) {
      const bool x = k == state_index::kCupX || k == state_index::die(0) || k == state_index::die(1) || k == state_index::die(2);
      EXPECT_DOUBLE_EQ(s[k], home[k] + (x ? shift : 0.0)) << "seed " << seed << ", " << state_names()[k];
    }
  }
  EXPECT_LE(widest, kPaperStartShift);
  EXPECT_GT(widest, 0.9 * kPaperStartShift);
  EXPECT_THAT(test::error_of([] { with_starts(WorldConfig{}, "papr"); }),
              HasSubstr("unknown start distribution \"papr\"; expected random or paper"));
}

}  // namespace
}  // namespace dicestack
