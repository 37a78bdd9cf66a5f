#include <dicestack/core/open_loop.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

OpenLoopProblem::OpenLoopProblem(const WorldConfig& world, const OpenLoopSettings& settings, int threads, Cluster& cluster)
    : world_(world), settings_(settings) {
  validate(world_);
  if (settings.steps < 1) throw ConfigError("open-loop steps must be at least 1, got " + std::to_string(settings.steps));
  if (settings.repeats < 1) throw ConfigError("open-loop repeats must be at least 1, got " + std::to_string(settings.repeats));
  world_.episode.max_steps = std::max(world_.episode.max_steps, settings.steps);
  start_ = paper_start_state(world_);
  goal_ = goal_state(world_);
  envs_.emplace(world_, threads);
  sequence_.emplace(world_, settings.steps, ActionBox::unit, [this](DiceEnv& env, const std::vector<Action>& a) { return run(env, a); });
  evaluator_.emplace(*envs_, threads, cluster);
}

std::vector<Action> OpenLoopProblem::actions(const double* x) const { return sequence_->actions(x); }

double OpenLoopProblem::run(DiceEnv& env, const std::vector<Action>& a) const {
  std::vector<State> trajectory(a.size());
  double total = 0.0;
  for (int r = 0; r < settings_.repeats; ++r) {
    env.reset_to(start_, derive_seed(settings_.seed, static_cast<std::uint64_t>(r)));
    for (std::size_t t = 0; t < a.size(); ++t) trajectory[t] = env.step(a[t]).observation;
    total += discounted_cost(trajectory, goal_, world_.cost);
  }
  return total / settings_.repeats;
}

double OpenLoopProblem::cost(const double* x) { return evaluator_->cost(*sequence_, x); }

std::vector<double> OpenLoopProblem::cost_batch(const Eigen::MatrixXd& xs) { return evaluator_->costs(*sequence_, xs); }

int OpenLoopProblem::evaluations() const { return evaluator_->evaluations(); }

std::vector<std::string> optimiser_names() { return minimiser_names(); }

OptimiseResult optimise(OpenLoopProblem& problem, const OptimiseOptions& o, const std::function<void(int, double)>& progress) {
  if (o.evaluations < 1) throw ConfigError("optimise: the budget must be at least 1 evaluation");
  const auto t0 = std::chrono::steady_clock::now();
  MinimiseOptions mo;
  mo.method = o.method;
  mo.evaluations = o.evaluations;
  mo.sigma0 = o.sigma0;
  mo.seed = o.seed;
  MinimiseResult m = minimise(problem.sequence(), problem.evaluator(), mo, progress);
  OptimiseResult r;
  r.best.assign(m.best.data(), m.best.data() + m.best.size());
  r.best_cost = m.best_cost;
  r.curve = std::move(m.curve);
  r.evaluations = problem.evaluations();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace dicestack
