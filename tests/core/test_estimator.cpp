// The state estimator between the sensors and the policy: it makes up an observation delay
// from the actions sent, filters sensor noise, and changes nothing where the sensing is nominal.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/perturbed_env.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

// A swing of the cup that scoops the dice now and then: contact-rich, and the same each run.
Action swing(int t) { return {3.0 * std::sin(0.11 * t), 1.5 * std::cos(0.07 * t), 0.8 * std::sin(0.05 * t)}; }

// The pose numbers (positions and angles), not the velocities.
bool is_pose(std::size_t k) { return k < state_index::kCupVx && (k < 3 || (k - 3) % 6 < 3); }

// Mean over an episode of |what the policy is shown - the state it stands for|, in units of
// each number's spread, over every number (or the poses alone). What is shown stands for the
// state the next action lands in, action_delay steps ahead.
double shown_error(const Perturbation& p, const EstimatorConfig& estimator, std::uint64_t seed, bool poses = false,
                   int steps = 200) {
  const WorldConfig w;
  DiceEnv pooled(w);
  PerturbedEnv env(pooled, p, seed);
  env.use_estimator(estimator);
  std::vector<State> shown{env.reset(seed)}, truth{env.env().get_state()};
  for (int t = 0; t < steps; ++t) {
    const PerturbedStep s = env.step(swing(t));
    shown.push_back(s.shown);
    truth.push_back(s.result.observation);
  }
  double sum = 0.0;
  int terms = 0;
  const auto lead = static_cast<std::size_t>(env.draw().action_delay);
  for (std::size_t t = 0; t + lead < truth.size(); ++t)
    for (std::size_t k = 0; k < kStateDim; ++k)
      if (!poses || is_pose(k)) {
        sum += std::abs(shown[t][k] - truth[t + lead][k]) / observation_spread()[k];
        ++terms;
      }
  return sum / terms;
}

TEST(Estimator, NamesAreParsedAtTheEdgeAndABadOneIsRefusedNamingTheChoices) {
  EXPECT_EQ(estimator_config("none").kind, EstimatorKind::none);
  EXPECT_EQ(estimator_config("kalman").kind, EstimatorKind::kalman);
  EXPECT_THAT(test::error_of([] { estimator_config("particles"); }), HasSubstr("not one of none, kalman, particle"));
  EXPECT_EQ(estimator_config("particle").kind, EstimatorKind::particle);
  EXPECT_EQ(estimator_config("particle").particles, 64);
  EXPECT_EQ(estimator_config("particle:8").particles, 8);
  EXPECT_EQ(estimator_config("particle:4096").particles, kMaxParticles);
  for (const char* bad : {"particle:0", "particle:4097", "particle:-1", "particle:+8", "particle: 8", "particle:8x", "particle:",
                          "particle:x", "particle:1e3", "particle:0000000008"})
    EXPECT_THAT(test::error_of([&] { estimator_config(bad); }), HasSubstr("a count of particles from 1 to 4096")) << bad;
}

TEST(Estimator, WithoutSensingFactorsThePolicySeesTheStateAsBefore) {
  const WorldConfig w;
  const Perturbation actuation = perturbation_factor("action_noise", "medium");
  EXPECT_EQ(make_estimator(estimator_config("kalman"), w, draw_perturbation(actuation, w, 1)), nullptr);
  EXPECT_EQ(shown_error(actuation, estimator_config("kalman"), 1), 0.0);
  EXPECT_NE(make_estimator(estimator_config("kalman"), w,
                           draw_perturbation(perturbation_factor("observation_noise", "easy"), w, 1)),
            nullptr);
  EXPECT_EQ(make_estimator(estimator_config("none"), w,
                           draw_perturbation(perturbation_factor("observation_noise", "easy"), w, 1)),
            nullptr);
}

// In the nominal world, without sensor noise, the model is never corrected, so it runs as the
// world does: the delay is made up exactly.
TEST(Estimator, MakesUpAnObservationDelayFromTheActionsThatRan) {
  const Perturbation late = perturbation_factor("observation_delay", "medium");
  for (std::uint64_t seed : {1u, 2u}) {
    EXPECT_GT(shown_error(late, estimator_config("none"), seed), 0.1) << "seed " << seed;
    EXPECT_EQ(shown_error(late, estimator_config("kalman"), seed), 0.0) << "seed " << seed;
  }
  // With the commands late too, the estimator's own queue knows what ran and what is queued:
  // what it shows is the state the next action lands in.
  Perturbation both;
  both.action_delay = 3;
  both.observation_delay = 4;
  EXPECT_EQ(shown_error(both, estimator_config("kalman"), 1), 0.0);
  // Under perturbed physics the model is the nominal world's, and the estimate comes close.
  Perturbation heavy = late;
  heavy.dice_mass = 0.5;
  const double raw = shown_error(heavy, estimator_config("none"), 3), estimated = shown_error(heavy, estimator_config("kalman"), 3);
  EXPECT_LT(estimated, 0.2 * raw) << "raw " << raw << ", estimated " << estimated;
}

// Under a delay in a world whose friction is not the nominal one, the forecast runs in the
// friction the observations show, closer to the truth than the nominal model's; under sensor
// noise no bank is kept, and the estimate is the nominal model's.
TEST(Estimator, UnderADelayItForecastsInTheFrictionTheObservationsShow) {
  Perturbation slippery = perturbation_factor("friction", "medium");
  slippery.action_delay = 3;
  slippery.observation_delay = 3;
  EstimatorConfig nominal = estimator_config("kalman");
  nominal.identify_friction = false;
  double identified = 0.0, assumed = 0.0;
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    identified += shown_error(slippery, estimator_config("kalman"), seed);
    assumed += shown_error(slippery, nominal, seed);
  }
  EXPECT_LT(identified, 0.8 * assumed) << "identified " << identified << ", nominal friction " << assumed;
  Perturbation noisy = slippery;
  noisy.observation_noise = 0.01;
  EXPECT_EQ(shown_error(noisy, estimator_config("kalman"), 1), shown_error(noisy, nominal, 1));
}

// The poses are what the simulator predicts best; the dice's velocities, made by contacts, it
// predicts least well, and there the estimate stays near the sensor's.
// A command delay alone: a policy trained without it is shown the state its action will meet,
// simulated through the commands queued before it.
TEST(Estimator, ShowsTheStateTheNextActionLandsInUnderACommandDelay) {
  for (const char* level : {"easy", "medium", "hard"}) {
    const Perturbation late = perturbation_factor("action_delay", level);
    EXPECT_GT(shown_error(late, estimator_config("none"), 1), 0.05) << level;
    EXPECT_EQ(shown_error(late, estimator_config("kalman"), 1), 0.0) << level;
  }
}

// On an arm, a policy in joint torques reads the links with the state. Behind both delays the
// estimator's model holds the links the encoders read (exact and at once) and the cup where
// they hold it, and shows the state the next torques land in with that state's links: far
// nearer both than the late observations and the encoders' links of now.
TEST(Estimator, MakesUpBothDelaysOnTheArmWithTheLinksOfTheStateItShows) {
  WorldConfig w;
  w.embodiment = Embodiment::arm;
  DiceEnv pooled(w);
  Perturbation late;
  late.action_delay = 3;
  late.observation_delay = 2;
  std::array<double, 2> state_error{}, link_error{};  // mean per number: kalman, none
  for (std::size_t run = 0; run < 2; ++run) {
    PerturbedEnv env(pooled, late, 1, ActionKind::joint_torque);
    env.use_estimator(estimator_config(run == 0 ? "kalman" : "none"));
    std::vector<State> shown{env.reset(1)}, truth{env.env().get_state()};
    std::vector<ArmLinks> shown_links{env.shown_links()}, links{env.env().world().arm_links()};
    for (int t = 0; t < 90; ++t) {  // held torques that sway the cup to and fro above the dice
      const auto tau = arm_torques(w.arm, env.env().world().arm_motion(), {0.8 * std::sin(0.1 * t), 0.3 * std::cos(0.1 * t)},
                                   0.2 * std::sin(0.07 * t), w.physics.control_dt, w.physics.gravity);
      const PerturbedStep step = env.step(Action::torques(tau));
      shown.push_back(step.shown);
      truth.push_back(step.result.observation);
      shown_links.push_back(env.shown_links());
      links.push_back(env.env().world().arm_links());
    }
    int terms = 0;
    for (std::size_t t = 0; t + 3 < truth.size(); ++t, ++terms) {
      for (std::size_t k = 0; k < kStateDim; ++k)
        state_error[run] += std::abs(shown[t][k] - truth[t + 3][k]) / observation_spread()[k] / kStateDim;
      for (std::size_t j = 0; j < 3; ++j)
        link_error[run] += (std::abs(shown_links[t].angles[j] - links[t + 3].angles[j]) +
                            std::abs(shown_links[t].rates[j] - links[t + 3].rates[j])) / 6.0;
    }
    state_error[run] /= terms;
    link_error[run] /= terms;
  }
  EXPECT_LT(state_error[0], 0.2 * state_error[1]) << "kalman " << state_error[0] << ", none " << state_error[1];
  EXPECT_LT(link_error[0], 0.2 * link_error[1]) << "kalman " << link_error[0] << ", none " << link_error[1];
  EXPECT_GT(link_error[1], 0.0);
  // A policy in the cup's actions on the arm is shown the encoders' links, behind the filter too.
  PerturbedEnv cup(pooled, late, 1, ActionKind::cup);
  cup.use_estimator(estimator_config("kalman"));
  cup.reset(1);
  for (int t = 0; t < 5; ++t) {
    cup.step(Action{0.1, 0.1, 0.0});
    EXPECT_EQ(cup.shown_links(), cup.env().world().arm_links()) << "step " << t;
  }
}

TEST(Estimator, FiltersSensorNoiseOnThePoses) {
  const Perturbation noisy = perturbation_factor("observation_noise", "medium");
  for (std::uint64_t seed : {1u, 2u}) {
    const double raw = shown_error(noisy, estimator_config("none"), seed, true);
    const double estimated = shown_error(noisy, estimator_config("kalman"), seed, true);
    EXPECT_LT(estimated, 0.6 * raw) << "seed " << seed << ": raw " << raw << ", estimated " << estimated;
    EXPECT_LT(shown_error(noisy, estimator_config("kalman"), seed), shown_error(noisy, estimator_config("none"), seed))
        << "seed " << seed << ": every number";
  }
}

TEST(Estimator, TheSameEpisodeGivesTheSameEstimatesBitForBit) {
  const Perturbation both = perturbation_level("medium");
  const WorldConfig w;
  for (const char* name : {"kalman", "particle:8"}) {
    DiceEnv a(w), b(w);
    PerturbedEnv x(a, both, 7), y(b, both, 7);
    x.use_estimator(estimator_config(name));
    y.use_estimator(estimator_config(name));
    EXPECT_TRUE(test::bit_equal(x.reset(7), y.reset(7))) << name;
    for (int t = 0; t < 60; ++t) EXPECT_TRUE(test::bit_equal(x.step(swing(t)).shown, y.step(swing(t)).shown)) << name << " " << t;
    EXPECT_TRUE(x.unseen().empty());  // the estimate is of the current state
  }
}

TEST(ParticleEstimator, FiltersSensorNoiseThroughTheContacts) {
  const Perturbation noisy = perturbation_factor("observation_noise", "medium");
  for (std::uint64_t seed : {1u, 2u}) {
    const double raw = shown_error(noisy, estimator_config("none"), seed);
    const double estimated = shown_error(noisy, estimator_config("particle:16"), seed);
    EXPECT_LT(estimated, 0.9 * raw) << "seed " << seed << ": raw " << raw << ", estimated " << estimated;
    EXPECT_LT(shown_error(noisy, estimator_config("particle:16"), seed, true), shown_error(noisy, estimator_config("none"), seed, true))
        << "seed " << seed << ": the poses";
  }
}

TEST(ParticleEstimator, IsTheFilterUnderSensorNoiseAndTheKalmanFilterMakesUpADelayWithoutIt) {
  const WorldConfig w;
  const auto noisy = make_estimator(estimator_config("particle:4"), w,
                                    draw_perturbation(perturbation_factor("observation_noise", "easy"), w, 1));
  EXPECT_NE(dynamic_cast<ParticleEstimator*>(noisy.get()), nullptr);
  const auto late = make_estimator(estimator_config("particle:4"), w,
                                   draw_perturbation(perturbation_factor("observation_delay", "medium"), w, 1));
  EXPECT_NE(dynamic_cast<KalmanEstimator*>(late.get()), nullptr);
  EXPECT_EQ(shown_error(perturbation_factor("observation_delay", "medium"), estimator_config("particle:4"), 1), 0.0);
  // Its estimates are its own, not the Kalman filter's.
  const Perturbation medium = perturbation_factor("observation_noise", "medium");
  EXPECT_NE(shown_error(medium, estimator_config("particle:8"), 1), shown_error(medium, estimator_config("kalman"), 1));
}

TEST(ParticleEstimator, ItsMemoryIsAWorldPerParticleAndOneToRunTheMeanOn) {
  EXPECT_EQ(estimator_bytes(estimator_config("none")), 0.0);
  EXPECT_EQ(estimator_bytes(estimator_config("kalman")), 27 * kEstimatorWorldBytes);  // its friction bank
  // Without sensor noise a particle filter is the Kalman filter, bank and all.
  EXPECT_EQ(estimator_bytes(estimator_config("particle:8")), 27 * kEstimatorWorldBytes);
  EXPECT_EQ(estimator_bytes(estimator_config("particle:64")), 65 * kEstimatorWorldBytes);
}

TEST(ParticleEstimator, ACountOutsideItsRangeIsRefusedWhereverTheConfigComesFrom) {
  const WorldConfig w;
  EstimatorConfig c = estimator_config("particle");
  c.particles = 0;
  const PerturbationDraw draw = draw_perturbation(perturbation_factor("observation_noise", "easy"), w, 1);
  EXPECT_THAT(test::error_of([&] { make_estimator(c, w, draw); }), HasSubstr("takes 1 to 4096 particles, got 0"));
}

}  // namespace
}  // namespace dicestack
