#include <gtest/gtest.h>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using test::bit_equal;

// Runs an episode, snapshots every `every` steps, and checks that a fresh World restored from
// each snapshot follows the uninterrupted run bit for bit for `follow` steps.
void expect_exact_continuations(const WorldConfig& c, std::uint64_t seed, int steps, int every, int follow) {
  const auto actions = test::random_actions(c, seed + 100, steps + follow);
  World run(c, random_start_state(c, seed));
  std::vector<State> states{run.state()};
  std::vector<std::pair<int, WorldSnapshot>> snaps;
  for (int t = 0; t < steps + follow; ++t) {
    if (t < steps && t % every == 0) snaps.emplace_back(t, run.snapshot());
    run.step(actions[static_cast<std::size_t>(t)]);
    states.push_back(run.state());
  }
  for (const auto& [t, snap] : snaps) {
    World restored(c);
    restored.restore(snap);
    ASSERT_TRUE(bit_equal(restored.state(), states[static_cast<std::size_t>(t)])) << "seed " << seed << " t " << t;
    for (int k = t; k < t + follow; ++k) {
      restored.step(actions[static_cast<std::size_t>(k)]);
      ASSERT_TRUE(bit_equal(restored.state(), states[static_cast<std::size_t>(k + 1)]))
          << "seed " << seed << ": snapshot at step " << t << " diverged at step " << k + 1;
    }
  }
}

TEST(Snapshot, RestoringContinuesBitForBit) {
  const WorldConfig c;
  for (std::uint64_t seed = 0; seed < 6; ++seed) expect_exact_continuations(c, seed, 150, 7, 40);
}

TEST(Snapshot, ExactWithSleepingBodies) {
  WorldConfig c;
  c.physics.allow_sleep = true;
  for (std::uint64_t seed = 0; seed < 3; ++seed) expect_exact_continuations(c, seed, 150, 11, 40);
}

TEST(Snapshot, RestoringIntoTheSameWorldRewinds) {
  const WorldConfig c;
  World w(c, random_start_state(c, 2));
  const auto actions = test::random_actions(c, 3, 60);
  for (int t = 0; t < 30; ++t) w.step(actions[static_cast<std::size_t>(t)]);
  const WorldSnapshot snap = w.snapshot();
  for (int t = 30; t < 60; ++t) w.step(actions[static_cast<std::size_t>(t)]);
  const State end = w.state();
  w.restore(snap);
  EXPECT_TRUE(bit_equal(w.state(), snap.state()));
  for (int t = 30; t < 60; ++t) w.step(actions[static_cast<std::size_t>(t)]);
  EXPECT_TRUE(bit_equal(w.state(), end));
}

TEST(Snapshot, CupVelocityIsPartOfTheSnapshot) {
  const WorldConfig c;
  World w(c);
  w.step({0.8, 0.05, 0.3});
  const WorldSnapshot snap = w.snapshot();
  World other(c);
  other.restore(snap);
  EXPECT_EQ(other.state()[state_index::kCupVx], w.state()[state_index::kCupVx]);
  EXPECT_EQ(other.state()[state_index::kCupW], w.state()[state_index::kCupW]);
}

TEST(Snapshot, EnvironmentSnapshotIncludesOutcomeAndNoise) {
  WorldConfig c;
  c.physics.action_noise = 0.2;
  DiceEnv env(c);
  env.reset(4);
  const auto actions = test::random_actions(c, 5, 80);
  for (int t = 0; t < 40; ++t) env.step(actions[static_cast<std::size_t>(t)]);
  const EnvSnapshot snap = env.snapshot();
  for (int t = 40; t < 80; ++t) env.step(actions[static_cast<std::size_t>(t)]);
  const State end = env.get_state();
  const Outcome outcome = env.outcome();
  DiceEnv other(c);
  other.restore(snap);
  EXPECT_EQ(other.t(), 40);
  for (int t = 40; t < 80; ++t) other.step(actions[static_cast<std::size_t>(t)]);
  EXPECT_TRUE(bit_equal(other.get_state(), end));
  EXPECT_EQ(other.outcome().wall_contact, outcome.wall_contact);
  EXPECT_EQ(other.outcome().dice_in_cup, outcome.dice_in_cup);
}

TEST(Snapshot, BareStateRestoreIsDeterministic) {
  const WorldConfig c;
  World w(c, random_start_state(c, 8));
  const auto actions = test::random_actions(c, 9, 60);
  for (int t = 0; t < 30; ++t) w.step(actions[static_cast<std::size_t>(t)]);
  const State mid = w.state();
  World a(c, mid), b(c, mid);
  for (int t = 30; t < 60; ++t) {
    a.step(actions[static_cast<std::size_t>(t)]);
    b.step(actions[static_cast<std::size_t>(t)]);
  }
  EXPECT_TRUE(bit_equal(a.state(), b.state()));
}

TEST(Snapshot, EmptySnapshotIsRejected) {
  World w{WorldConfig{}};
  EXPECT_THROW(w.restore(WorldSnapshot{}), InputError);
  EXPECT_THROW(WorldSnapshot{}.to_bytes(), InputError);
}

// Snapshot -> bytes -> snapshot continues like the original, outcome and noise stream included.
TEST(Snapshot, BytesRoundTripIsExact) {
  WorldConfig c;
  c.physics.action_noise = 0.2;
  DiceEnv env(c);
  env.reset(6);
  const auto actions = test::random_actions(c, 7, 90);
  for (int t = 0; t < 45; ++t) env.step(actions[static_cast<std::size_t>(t)]);
  const std::string bytes = to_bytes(env.snapshot());
  EXPECT_EQ(to_bytes(env_snapshot_from_bytes(bytes)), bytes);
  for (int t = 45; t < 90; ++t) env.step(actions[static_cast<std::size_t>(t)]);
  DiceEnv other(c);
  other.restore(env_snapshot_from_bytes(bytes));
  EXPECT_EQ(other.t(), 45);
  for (int t = 45; t < 90; ++t) other.step(actions[static_cast<std::size_t>(t)]);
  EXPECT_TRUE(bit_equal(other.get_state(), env.get_state()));
  EXPECT_EQ(other.outcome().steps, env.outcome().steps);
  EXPECT_EQ(other.outcome().dice_in_cup, env.outcome().dice_in_cup);
  EXPECT_EQ(other.outcome().wall_contact, env.outcome().wall_contact);
}

TEST(Snapshot, DamagedBytesAreRefused) {
  DiceEnv env{WorldConfig{}};
  env.reset(1);
  env.step({0.5, 0.0, 0.1});
  const std::string bytes = to_bytes(env.snapshot());
  EXPECT_THROW(env_snapshot_from_bytes(""), InputError);
  EXPECT_THROW(env_snapshot_from_bytes(bytes.substr(0, bytes.size() / 2)), InputError);
  for (std::size_t at : {std::size_t{0}, std::size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x40);
    EXPECT_THROW(env_snapshot_from_bytes(damaged), InputError) << "byte " << at;
  }
  EXPECT_THROW(WorldSnapshot::from_bytes(bytes), InputError);  // an environment record is not a world's
  try {
    std::string damaged = bytes;
    damaged[20] = static_cast<char>(damaged[20] ^ 1);
    env_snapshot_from_bytes(damaged);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("checksum"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dicestack
