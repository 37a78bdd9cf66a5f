// The arm embodiment: a planar three-link arm with a wrist holds the cup; its rest posture, the
// cup controller that makes it move the cup as a floating cup would move, exact snapshots, wall
// contact by its links, and the world file that names it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
namespace si = state_index;

WorldConfig arm_world() {
  WorldConfig c;
  c.embodiment = Embodiment::arm;
  return c;
}

TEST(Arm, TheRestPostureHoldsTheWristWhereAsked) {
  const ArmConfig arm;
  for (const Vec2 wrist : {Vec2{4.5, 1.5}, Vec2{2.0, 2.5}, Vec2{7.0, 4.0}, Vec2{4.5, 5.0}}) {
    const ArmPosture p = arm_posture(arm, wrist);
    ASSERT_TRUE(p.reached) << wrist.x << ", " << wrist.y;
    EXPECT_NEAR(p.joints[3].x, wrist.x, 1e-9);
    EXPECT_NEAR(p.joints[3].y, wrist.y, 1e-9);
    EXPECT_NEAR(p.joints[0].x, arm.base.x, 0.0);
    // Neither folded nor stretched: every elbow within its limits, with room.
    for (std::size_t j = 1; j < 3; ++j) {
      const double bend = std::remainder(p.link_angles[j] - p.link_angles[j - 1], 2 * M_PI);
      EXPECT_LT(std::abs(bend), arm.joint_upper[j] - 0.3) << wrist.x << ", " << wrist.y << ", joint " << j;
    }
    EXPECT_EQ(arm_posture(arm, wrist).link_angles, p.link_angles);  // the same arm each time
  }
  EXPECT_FALSE(arm_posture(arm, {4.5, -20.0}).reached);
}

// The link rates move the wrist at the velocity asked (the damping aside).
TEST(Arm, LinkRatesMoveTheWristAtTheVelocityAsked) {
  const ArmConfig arm;
  const ArmPosture p = arm_posture(arm, {4.0, 2.0});
  const Vec2 v{0.7, -0.4};
  const auto rates = arm_link_rates(arm, p.link_angles, v);
  double vx = 0.0, vy = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    vx -= arm.link_lengths[i] * std::sin(p.link_angles[i]) * rates[i];
    vy += arm.link_lengths[i] * std::cos(p.link_angles[i]) * rates[i];
  }
  EXPECT_NEAR(vx, v.x, 1e-3);
  EXPECT_NEAR(vy, v.y, 1e-3);
}

TEST(Arm, TheArmWorldStartsWhereTheStateSaysWithTheLinksClearOfTheWalls) {
  const WorldConfig c = arm_world();
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const State start = random_start_state(c, seed);
    World w(c, start);
    EXPECT_TRUE(test::bit_equal(w.state(), World(WorldConfig{}, start).state()));  // the cup and dice as without the arm
    EXPECT_FALSE(w.touching_walls()) << "seed " << seed;
    int links = 0;
    for (const auto& o : w.outlines()) links += o.kind == ShapeKind::arm;
    EXPECT_EQ(links, 3);
  }
}

// Without contacts, the arm moves the cup as a floating cup moves: its velocity plus the action,
// then gravity's pull.
TEST(Arm, InFreeSpaceTheCupMovesAsTheFloatingCupDoes) {
  State lifted = paper_start_state(WorldConfig{});
  lifted[si::kCupY] += 1.5;  // clear of the dice
  World floating(WorldConfig{}, lifted), held(arm_world(), lifted);
  for (int t = 0; t < 20; ++t) {
    const Action a{0.3 * std::sin(0.3 * t), 0.2, 0.4 * std::cos(0.2 * t)};
    floating.step(a);
    held.step(a);
    for (std::size_t k : {si::kCupX, si::kCupY, si::kCupAngle, si::kCupVx, si::kCupVy, si::kCupW})
      EXPECT_NEAR(held.state()[k], floating.state()[k], 0.02) << "step " << t << ", number " << k;
  }
  for (double torque : held.arm_joint_torques()) EXPECT_TRUE(std::isfinite(torque));
}

// A world rebuilt with the links its encoders read holds them, and the cup where they hold it;
// the 24 numbers alone rebuild the arm in its rest posture. A floating cup or a link that is not
// finite is refused.
TEST(Arm, AStateRebuiltWithItsLinksHoldsThemAndTheCupWhereTheyHoldIt) {
  const WorldConfig c = arm_world();
  World run(c, paper_start_state(c));
  for (int t = 0; t < 10; ++t) run.step(Action{0.1, 0.05, 0.2});
  const State s = run.state();
  const ArmLinks links = run.arm_links();
  World rebuilt(c);
  rebuilt.set_state(s, links);
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_NEAR(rebuilt.arm_links().angles[j], links.angles[j], 1e-6);
    EXPECT_NEAR(rebuilt.arm_links().rates[j], links.rates[j], 1e-5);
  }
  // The cup within the joints' slack of where it was (its velocity the links' own), the dice
  // exactly where they were.
  for (std::size_t k = 0; k < kStateDim; ++k) EXPECT_NEAR(rebuilt.state()[k], s[k], k < 3 || k > 20 ? 1e-2 : 1e-6) << k;
  World rest(c);
  rest.set_state(s);
  double moved = 0.0;
  for (std::size_t j = 0; j < 3; ++j) moved += std::abs(rest.arm_links().angles[j] - links.angles[j]);
  EXPECT_GT(moved, 1e-3) << "the swing moved the arm out of its rest posture";
  World floating{WorldConfig{}};
  EXPECT_THAT(test::error_of([&] { floating.set_state(s, links); }), HasSubstr("floating cup"));
  ArmLinks bad = links;
  bad.rates[1] = std::nan("");
  EXPECT_THAT(test::error_of([&] { rebuilt.set_state(s, bad); }), HasSubstr("not finite"));
}

TEST(Arm, RestoringASnapshotContinuesBitForBit) {
  const WorldConfig c = arm_world();
  const auto actions = test::random_actions(c, 5, 80);
  World run(c, random_start_state(c, 5));
  std::vector<State> states{run.state()};
  WorldSnapshot at30;
  for (int t = 0; t < 80; ++t) {
    if (t == 30) at30 = WorldSnapshot::from_bytes(run.snapshot().to_bytes());
    run.step(actions[static_cast<std::size_t>(t)]);
    states.push_back(run.state());
  }
  World restored(c);
  restored.restore(at30);
  for (int t = 30; t < 80; ++t) {
    restored.step(actions[static_cast<std::size_t>(t)]);
    ASSERT_TRUE(test::bit_equal(restored.state(), states[static_cast<std::size_t>(t + 1)])) << "step " << t + 1;
  }
  // A snapshot of one embodiment does not restore into the other.
  World cup(WorldConfig{});
  EXPECT_ANY_THROW(cup.restore(at30));
}

// A floating cup's snapshot record of version 1 (before the arm: no link count) still restores.
TEST(Arm, AVersionOneSnapshotRecordOfTheFloatingCupIsRead) {
  const WorldConfig c;
  World run(c, random_start_state(c, 4));
  for (int t = 0; t < 10; ++t) run.step({0.2, 0.1, 0.0});
  const std::string v2 = run.snapshot().to_bytes();
  // Marker, version, 24 numbers, the link count (0): version 1 is the same less the count.
  const std::size_t count_at = 4 + 4 + 24 * 8;
  std::string v1 = v2.substr(0, count_at) + v2.substr(count_at + 4, v2.size() - 8 - count_at - 4);
  const std::uint32_t one = 1;
  v1.replace(4, 4, reinterpret_cast<const char*>(&one), 4);
  const std::uint64_t sum = fnv1a(v1);
  v1.append(reinterpret_cast<const char*>(&sum), 8);
  World restored(c);
  restored.restore(WorldSnapshot::from_bytes(v1));
  run.step({0.1, 0.0, 0.1});
  restored.step({0.1, 0.0, 0.1});
  EXPECT_TRUE(test::bit_equal(restored.state(), run.state()));
}

// The joint_torque controller: the torques hold through the step, each within its limit; the
// floating cup refuses them; the environment clips them to the arm's limits.
TEST(Arm, JointTorquesAreHeldThroughTheStepWithinTheirLimits) {
  const WorldConfig c = arm_world();
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;  // clear of the dice
  World limp(c, lifted), turned(c, lifted);
  for (int t = 0; t < 3; ++t) {
    limp.step(Action::torques({}));
    turned.step(Action::torques({0.0, 0.0, 0.0, 1e6}));
    EXPECT_EQ(turned.arm_joint_torques(), (std::array<double, 4>{0.0, 0.0, 0.0, c.arm.torque_limit[3]})) << "step " << t;
  }
  EXPECT_LT(limp.state()[si::kCupY], lifted[si::kCupY] - 0.01) << "without torques the arm falls";
  EXPECT_GT(turned.state()[si::kCupAngle], limp.state()[si::kCupAngle] + 0.05) << "the wrist's torque turns the cup";

  World floating(WorldConfig{}, lifted);
  try {
    floating.step(Action::torques({1.0, 0.0, 0.0, 0.0}));
    ADD_FAILURE() << "a floating cup took joint torques";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("embodiment"));
  }

  DiceEnv env(c);
  env.reset_to(lifted);
  const StepResult r = env.step(Action::torques({-1e9, 1e9, 0.5, 0.0}));
  EXPECT_EQ(r.applied, Action::torques({-c.arm.torque_limit[0], c.arm.torque_limit[1], 0.5, 0.0}));
  EXPECT_EQ(env.torque_space().high, c.arm.torque_limit);
}

// A joint at its speed limit gets no torque that would turn it faster.
TEST(Arm, AJointAtItsSpeedLimitIsNotDrivenFaster) {
  WorldConfig c = arm_world();
  c.arm.speed_limit[3] = 2.0;  // rad/s: the wrist reaches it within a step at its torque limit
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;
  World w(c, lifted);
  bool withheld = false;
  for (int t = 0; t < 10; ++t) {
    w.step(Action::torques({0.0, 0.0, 0.0, 1e6}));
    const double wrist_rate = w.state()[si::kCupW] - w.arm_link_rates()[2];
    EXPECT_LT(wrist_rate, 2.0 + 1.0) << "step " << t;  // at most one substep of the limit's torque beyond it
    withheld = withheld || w.arm_joint_torques()[3] == 0.0;
  }
  EXPECT_TRUE(withheld);
}

// The torque change asked for a velocity change gives it, in free space.
TEST(Arm, ATorqueChangeChangesTheCupsVelocityByWhatWasAsked) {
  const WorldConfig c = arm_world();
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;
  World base(c, lifted), changed(c, lifted);
  const std::array<double, 4> hold{0.0, 0.0, 0.0, 0.0};
  const auto delta = arm_torque_change(c.arm, base.arm_motion(), {0.3, -0.2}, 0.5, c.physics.control_dt);
  base.step(Action::torques(hold));
  changed.step(Action::torques({delta[0], delta[1], delta[2], delta[3]}));
  EXPECT_NEAR(changed.state()[si::kCupVx] - base.state()[si::kCupVx], 0.3, 0.03);
  EXPECT_NEAR(changed.state()[si::kCupVy] - base.state()[si::kCupVy], -0.2, 0.03);
  EXPECT_NEAR(changed.state()[si::kCupW] - base.state()[si::kCupW], 0.5, 0.05);
}

// Within the limits the law's inverse gives back what it was asked, so a teacher's torques
// label the cup motion and posture that the law turns back into them.
TEST(Arm, TheLawsInverseGivesBackTheVelocityAndPostureItWasAsked) {
  const WorldConfig c = arm_world();
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;
  lifted[si::kCupVx] = 0.4;
  World w(c, lifted);
  const ArmMotion now = w.arm_motion();
  const double dt = c.physics.control_dt;
  const std::array<double, 4> torques = arm_torques(c.arm, now, {0.6, 0.3}, -0.4, dt, c.physics.gravity, 2.5);
  for (std::size_t j = 0; j < 4; ++j) ASSERT_LT(std::abs(torques[j]), c.arm.torque_limit[j]) << "within the limits, joint " << j;
  const LawRequest back = arm_torques_inverse(c.arm, now, torques, dt, c.physics.gravity);
  EXPECT_NEAR(back.cup.velocity.x, 0.6, 1e-9);
  EXPECT_NEAR(back.cup.velocity.y, 0.3, 1e-9);
  EXPECT_NEAR(back.cup.angular_velocity, -0.4, 1e-9);
  EXPECT_NEAR(back.posture, 2.5, 1e-9);
}

// Any torques within the limits are something the law can be asked: the four numbers give them
// back, whichever way they move the spare degree of freedom.
TEST(Arm, AnyTorquesWithinTheLimitsAreWhatTheLawWasAsked) {
  const WorldConfig c = arm_world();
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;
  World w(c, lifted);
  const ArmMotion now = w.arm_motion();
  const double dt = c.physics.control_dt;
  std::array<double, 4> torques = arm_torques(c.arm, now, {0.0, 0.0}, 0.0, dt, c.physics.gravity);
  torques[0] += 300.0;  // a shoulder push the law's posture would not give
  torques[2] -= 40.0;
  for (std::size_t j = 0; j < 4; ++j) ASSERT_LT(std::abs(torques[j]), c.arm.torque_limit[j]) << "within the limits, joint " << j;
  const LawRequest asked = arm_torques_inverse(c.arm, now, torques, dt, c.physics.gravity);
  const std::array<double, 4> again = arm_torques(c.arm, now, asked.cup.velocity, asked.cup.angular_velocity, dt, c.physics.gravity, asked.posture);
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(again[j], torques[j], 1e-6 * c.arm.torque_limit[j]) << "joint " << j;
  EXPECT_GT(std::abs(asked.posture), 1.0) << "the push moves the posture";
}

// The posture's axis moves the links and not the cup: the Jacobian of the cup's centre and angle
// sends it to zero.
TEST(Arm, ThePostureAxisLeavesTheCupWhereItIs) {
  const WorldConfig c = arm_world();
  const World w(c, paper_start_state(c));
  const std::array<double, 4> angles = w.arm_motion().angles;
  const std::array<double, 4> axis = arm_posture_axis(c.arm, angles);
  double x = 0.0, y = 0.0, norm = 0.0;
  for (std::size_t j = 0; j < 3; ++j) {
    x -= c.arm.link_lengths[j] * std::sin(angles[j]) * axis[j];
    y += c.arm.link_lengths[j] * std::cos(angles[j]) * axis[j];
  }
  for (double a : axis) norm += a * a;
  EXPECT_NEAR(x, 0.0, 1e-12);
  EXPECT_NEAR(y, 0.0, 1e-12);
  EXPECT_EQ(axis[3], 0.0);
  EXPECT_NEAR(norm, 1.0, 1e-12);
}

// Asked for more than its torques can give, the cup controller scales the task's share of them
// down: the cup moves the way it was asked and the arm keeps its posture. Clipping each joint
// alone sent the cup elsewhere (asked left and up, it went right and up) and turned the arm.
TEST(Arm, AVelocityChangeBeyondTheTorqueLimitsKeepsItsDirectionAndTheArmsPosture) {
  const WorldConfig c = arm_world();
  State lifted = paper_start_state(c);
  lifted[si::kCupY] += 1.5;  // clear of the dice
  const std::array<Action, 3> asked{Action{-50.0, 0.0, 0.0}, Action{-30.0, 30.0, 0.0}, Action{0.0, 0.0, -60.0}};
  for (const Action& a : asked) {
    World w(c, lifted);
    const double last_link = w.arm_link_angles()[2];
    w.step(a);
    const State& s = w.state();
    const std::array<double, 3> got{s[si::kCupVx], s[si::kCupVy], s[si::kCupW]};
    const double norm = std::hypot(a[0], a[1], a[2]), along = (got[0] * a[0] + got[1] * a[1] + got[2] * a[2]) / norm;
    EXPECT_GT(along, 1.0) << "the cup moves the way it was asked, " << a[0] << ", " << a[1] << ", " << a[2];
    for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(got[k], along * a[k] / norm, 0.1 * along) << "component " << k;
    EXPECT_NEAR(w.arm_link_angles()[2], last_link, 0.02) << "the last link keeps its direction";
    bool saturated = false;
    for (std::size_t j = 0; j < 4; ++j) saturated = saturated || std::abs(w.arm_joint_torques()[j]) >= c.arm.torque_limit[j] - 1e-6;
    EXPECT_TRUE(saturated) << "a joint is at its limit";
  }
}

TEST(Arm, ALinkOnAWallIsWallContact) {
  WorldConfig c = arm_world();
  State s = paper_start_state(c);
  s[si::kCupX] = 1.2;  // the arm leans left: drive the cup into the left wall
  World w(c, s);
  bool wall = false;
  for (int t = 0; t < 60 && !wall; ++t) wall = w.step({-1.0, 0.4, 0.0});
  EXPECT_TRUE(wall);
}

TEST(Arm, TheWorldFileNamesTheEmbodimentAndOlderFilesAreTheFloatingCup) {
  const WorldConfig c = arm_world();
  const WorldConfig back = world_config_from_json(to_json(c));
  EXPECT_EQ(back, c);
  EXPECT_NE(world_hash(c), world_hash(WorldConfig{}));
  // A version 2 file has neither field: the floating cup.
  std::string v2 = to_json(WorldConfig{});
  v2.replace(v2.find("\"version\": 3"), 12, "\"version\": 2");
  const auto drop = [&](const std::string& key) {
    const auto at = v2.find("\"" + key + "\"");
    const auto end = key == "arm" ? v2.find('}', at) + 1 : v2.find('\n', at) - 1;
    v2.erase(at, end - at + 1);
  };
  drop("arm");
  drop("embodiment");
  EXPECT_EQ(world_config_from_json(v2).embodiment, Embodiment::cup);
  // Out of reach, or an unknown embodiment: refused, naming the field.
  WorldConfig short_arm = c;
  short_arm.arm.link_lengths = {1.0, 1.0, 0.5};
  EXPECT_THAT(test::error_of([&] { validate(short_arm); }), HasSubstr("arm.link_lengths"));
  std::string text = to_json(c);
  text.replace(text.find("\"arm\","), 6, "\"robot\",");
  EXPECT_THAT(test::error_of([&] { world_config_from_json(text); }), HasSubstr("must be \"cup\" or \"arm\""));
}

}  // namespace
}  // namespace dicestack
