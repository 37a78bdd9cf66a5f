#include <dicestack/core/arm_oscillation.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include <Eigen/Core>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kServoHz = 1.5;   // the servo's natural frequency: well under the 30 Hz control rate
constexpr double kEaseSeconds = 1.0;

// The pattern's angle, rate and acceleration of joint j at time `s` (seconds).
struct Reference {
  double angle = 0.0, rate = 0.0, accel = 0.0;
};

Reference reference(const JointOscillation& p, std::size_t j, double s) {
  const double at = std::min(s, p.stop);
  const double w = 2.0 * kPi * p.frequency[j];
  Reference r;
  r.angle = p.offset[j] * std::min(1.0, at / kEaseSeconds) + p.amplitude[j] * (std::sin(w * at + p.phase[j]) - std::sin(p.phase[j]));
  if (s < p.stop) {
    r.rate = p.amplitude[j] * w * std::cos(w * s + p.phase[j]) + (s < kEaseSeconds ? p.offset[j] / kEaseSeconds : 0.0);
    r.accel = -p.amplitude[j] * w * w * std::sin(w * s + p.phase[j]);
  }
  return r;
}

}  // namespace

JointOscillation JointOscillation::from_search(const double* x) {
  JointOscillation p;
  for (std::size_t j = 0; j < 4; ++j) {
    p.offset[j] = 0.5 * x[j];
    p.amplitude[j] = 0.5 * std::abs(x[4 + j]);
    p.frequency[j] = std::abs(x[8 + j]);
    p.phase[j] = kPi * x[12 + j];
  }
  p.stop = std::max(0.0, 4.0 + 4.0 * x[16]);
  return p;
}

std::string JointOscillation::to_text() const {
  static constexpr const char* kNames[] = {"shoulder", "elbow", "second elbow", "wrist"};
  std::string out;
  char line[160];
  for (std::size_t j = 0; j < 4; ++j) {
    std::snprintf(line, sizeof line, "%-13s offset %+.3f rad, amplitude %.3f rad, %.3f Hz, phase %+.3f rad\n", kNames[j], offset[j],
                  amplitude[j], frequency[j], phase[j]);
    out += line;
  }
  std::snprintf(line, sizeof line, "stops after %.2f s\n", stop);
  return out + line;
}

std::array<double, 4> arm_joint_angles(const World& world) {
  return arm_joint_angles_of(world.arm_link_angles(), world.state()[state_index::kCupAngle]);
}

Action oscillation_torques(const World& world, const JointOscillation& pattern, const std::array<double, 4>& start, int t) {
  const WorldConfig& c = world.config();
  if (c.embodiment != Embodiment::arm) throw InputError("a joint oscillation needs a world whose embodiment is \"arm\"");
  const ArmMotion now = world.arm_motion();
  // Computed torque: each joint's pattern acceleration plus a critically damped PD of the servo's
  // frequency towards its angle and rate, the chain's dynamics turning those into torques.
  const double time = (t + 0.5) * c.physics.control_dt;  // the middle of the step the torques hold through
  const double wn = 2.0 * kPi * kServoHz;
  std::array<double, 4> accel{};
  double absolute = 0.0;
  for (std::size_t j = 0; j < 4; ++j) {
    const Reference r = reference(pattern, j, time);
    const double q = (j == 0 ? now.angles[0] : now.angles[j] - now.angles[j - 1]) - start[j];
    const double qd = j == 0 ? now.rates[0] : now.rates[j] - now.rates[j - 1];
    absolute += r.accel + wn * wn * (r.angle - q) + 2.0 * wn * (r.rate - qd);
    accel[j] = absolute;
  }
  return Action::torques(arm_joint_space_torques(c.arm, now, accel, c.physics.gravity));
}

OscillationEpisode run_oscillation(DiceEnv& env, const JointOscillation& pattern, const State& start, std::uint64_t seed) {
  env.reset_to(start, seed);
  const std::array<double, 4> q0 = arm_joint_angles(env.world());
  OscillationEpisode out;
  for (int t = 0; t < env.config().episode.max_steps; ++t) {
    const StepResult r = env.step(oscillation_torques(env.world(), pattern, q0, t));
    out.cost -= r.reward;
    if (r.terminated) break;  // a realistic success held: the episode ends as evaluate ends it
  }
  out.outcome = env.outcome();
  return out;
}

double OscillationEpisode::search_cost() const {
  return cost - outcome.dice_in_cup / 3.0 - (outcome.realistic_success() ? 2.0 : 0.0) + (outcome.wall_contact ? 1.0 : 0.0);
}

OscillationResult search_oscillation(const WorldConfig& world, const OscillationSearch& search,
                                     const std::function<void(int, double)>& progress) {
  if (world.embodiment != Embodiment::arm) throw ConfigError("the joint oscillation search needs the arm embodiment");
  if (search.starts < 1 || search.evaluations < 1)
    throw ConfigError("the joint oscillation search needs at least 1 start and 1 evaluation");
  std::vector<State> starts;
  for (int i = 0; i < search.starts; ++i)
    starts.push_back(random_start_state(world, training_start_seed(search.seed, static_cast<std::uint64_t>(i))));
  EnvPool envs(world, search.threads);
  auto mean_cost = [&](const Eigen::MatrixXd& xs) {
    std::vector<double> costs(static_cast<std::size_t>(xs.rows()));
    parallel_for(costs.size(), search.threads, [&](std::size_t i, int worker) {
      const Eigen::VectorXd x = xs.row(static_cast<Eigen::Index>(i)).transpose();
      const JointOscillation p = JointOscillation::from_search(x.data());
      double sum = 0.0;
      for (std::size_t k = 0; k < starts.size(); ++k) sum += run_oscillation(envs.at(worker), p, starts[k], k).search_cost();
      costs[i] = sum / static_cast<double>(starts.size());
    });
    return costs;
  };
  // CMA-ES from the arm held still, then, each time it settles before the budget is spent, again
  // from a point drawn in [-1, 1]^17 (the cost is flat in places, where one run stops early).
  OscillationResult result;
  result.best_cost = std::numeric_limits<double>::infinity();
  Rng draws(derive_seed(search.seed, 1));
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(JointOscillation::kParameters);
  for (int run = 0; result.evaluations < search.evaluations; ++run) {
    CmaesOptions options;
    options.sigma0 = search.sigma0;
    options.max_evaluations = search.evaluations - result.evaluations;
    options.seed = derive_seed(search.seed, 2 + static_cast<std::uint64_t>(run));
    Cmaes cmaes(x0, options);
    while (!cmaes.done()) {
      cmaes.tell(mean_cost(cmaes.ask()));
      if (progress) progress(result.evaluations + cmaes.evaluations(), std::min(result.best_cost, cmaes.best_value()));
    }
    if (cmaes.evaluations() == 0) break;
    result.evaluations += cmaes.evaluations();
    if (cmaes.best_value() < result.best_cost) {
      result.best_cost = cmaes.best_value();
      result.best = JointOscillation::from_search(cmaes.best().data());
    }
    for (Eigen::Index k = 0; k < x0.size(); ++k) x0(k) = draws.uniform(-1.0, 1.0);
  }
  return result;
}

}  // namespace dicestack
