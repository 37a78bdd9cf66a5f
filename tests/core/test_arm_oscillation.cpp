// The open-loop question on the arm: the joint servo holds a pattern, the search is the same on
// any number of threads.
#include <gtest/gtest.h>

#include <cmath>

#include <dicestack/core/arm_oscillation.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>

namespace dicestack {
namespace {

WorldConfig oscillating_arm_world() {
  WorldConfig c;
  c.embodiment = Embodiment::arm;
  return c;
}

// In free space a still pattern holds the arm where it started, and a swinging elbow follows
// its sine.
TEST(ArmOscillation, TheServoHoldsEachJointOnItsPattern) {
  const WorldConfig c = oscillating_arm_world();
  DiceEnv env(c);
  State start = paper_start_state(c);
  start[state_index::kCupY] += 1.5;  // clear of the dice: nothing but the servo moves the arm
  JointOscillation swing;
  swing.amplitude[1] = 0.2;
  swing.frequency[1] = 0.5;
  swing.stop = 100.0;
  for (const JointOscillation& p : {JointOscillation{}, swing}) {
    env.reset_to(start, 0);
    const auto q0 = arm_joint_angles(env.world());
    double worst = 0.0;
    for (int t = 0; t < 90; ++t) {
      env.step(oscillation_torques(env.world(), p, q0, t));
      const double s = (t + 1) * c.physics.control_dt;
      const auto q = arm_joint_angles(env.world());
      const double want = p.amplitude[1] * std::sin(2.0 * M_PI * p.frequency[1] * s);
      worst = std::max(worst, std::abs(q[1] - q0[1] - want));
      for (std::size_t j : {0u, 2u, 3u}) worst = std::max(worst, std::abs(q[j] - q0[j]));
    }
    EXPECT_LT(worst, p.amplitude[1] > 0.0 ? 0.03 : 1e-4) << "amplitude " << p.amplitude[1];
  }
  DiceEnv floating{WorldConfig{}};
  EXPECT_THROW(oscillation_torques(floating.world(), swing, {}, 0), InputError);
}

TEST(ArmOscillation, TheSearchIsTheSameOnAnyNumberOfThreads) {
  OscillationSearch search;
  search.starts = 2;
  search.evaluations = 24;
  WorldConfig c = oscillating_arm_world();
  c.episode.max_steps = 40;
  search.threads = 1;
  const OscillationResult one = search_oscillation(c, search);
  search.threads = 2;
  const OscillationResult two = search_oscillation(c, search);
  EXPECT_EQ(one.best_cost, two.best_cost);
  EXPECT_EQ(one.best.to_text(), two.best.to_text());
  EXPECT_THROW(search_oscillation(WorldConfig{}, search), ConfigError);
}

}  // namespace
}  // namespace dicestack
