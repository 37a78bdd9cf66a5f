#include <dicestack/learners/corrector.hpp>

#include <algorithm>
#include <cmath>

#include <pagmo/algorithms/de.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

double window_cost(DiceEnv& env, const CorrectionProblem& problem, const std::vector<Action>& actions,
                   std::vector<State>* states) {
  env.restore(problem.start);
  if (states) states->clear();
  double cost = 0.0;
  const CostConfig& c = env.config().cost;
  for (std::size_t j = 0; j < problem.target.size(); ++j) {
    if (states) states->push_back(env.get_state());
    env.step(actions[j]);
    cost += tracking_distance_sq(env.get_state(), problem.target[j], c);
  }
  return cost;
}

namespace {

// The search space: x = action / scale for the window's actions in order, boxed by the limits.
class ScaledWindow {
 public:
  ScaledWindow(const WorldConfig& world, std::size_t steps) : world_(world), steps_(steps) {}

  std::size_t dim() const { return steps_ * kActionDim; }
  double bound(std::size_t i) const { return world_.action.limit[i % kActionDim] / world_.action.scale[i % kActionDim]; }
  double clip(std::size_t i, double v) const { return std::clamp(v, -bound(i), bound(i)); }

  std::vector<Action> actions(const double* x) const {
    std::vector<Action> out(steps_);
    for (std::size_t i = 0; i < dim(); ++i) out[i / kActionDim][i % kActionDim] = clip(i, x[i]) * world_.action.scale[i % kActionDim];
    return out;
  }
  Eigen::VectorXd point(const std::vector<Action>& actions) const {
    Eigen::VectorXd x(static_cast<Eigen::Index>(dim()));
    for (std::size_t i = 0; i < dim(); ++i)
      x[static_cast<Eigen::Index>(i)] = clip(i, actions[i / kActionDim][i % kActionDim] / world_.action.scale[i % kActionDim]);
    return x;
  }

 private:
  const WorldConfig& world_;
  std::size_t steps_;
};

// Both correctors keep the warm start as the answer unless they find better.
Correction finish(DiceEnv& env, const CorrectionProblem& p, std::vector<Action> best, double warm_cost, int evaluations) {
  Correction c;
  c.actions = std::move(best);
  c.cost = window_cost(env, p, c.actions, &c.states);  // deterministic: equals best_cost
  c.warm_cost = warm_cost;
  c.evaluations = evaluations + 1;
  return c;
}

class CmaesCorrector final : public Corrector {
 public:
  explicit CmaesCorrector(const CorrectorOptions& o) : options_(o) {}

  Correction correct(DiceEnv& env, const CorrectionProblem& p, std::uint64_t seed) const override {
    const ScaledWindow space(env.config(), p.target.size());
    std::vector<Action> best = space.actions(space.point(p.warm).data());
    const double warm_cost = window_cost(env, p, best);
    CmaesOptions o;
    o.population = options_.population;
    o.sigma0 = options_.sigma0;
    o.max_iterations = options_.iterations;
    o.seed = seed;
    Cmaes es(space.point(p.warm), o);
    std::vector<double> values;
    while (!es.done()) {
      const Eigen::MatrixXd& x = es.ask();
      values.resize(static_cast<std::size_t>(x.rows()));
      for (Eigen::Index r = 0; r < x.rows(); ++r) {
        const Eigen::VectorXd row = x.row(r).transpose();
        values[static_cast<std::size_t>(r)] = window_cost(env, p, space.actions(row.data()));
      }
      es.tell(values);
    }
    if (es.best_value() < warm_cost) best = space.actions(es.best().data());
    return finish(env, p, std::move(best), warm_cost, es.evaluations() + 1);
  }

 private:
  CorrectorOptions options_;
};

// pagmo's differential evolution (DE/rand/1/exp by default) on the same scaled box.
struct WindowProblem {
  DiceEnv* env = nullptr;
  const CorrectionProblem* problem = nullptr;
  const ScaledWindow* space = nullptr;

  pagmo::vector_double fitness(const pagmo::vector_double& x) const {
    return {window_cost(*env, *problem, space->actions(x.data()))};
  }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    pagmo::vector_double lo(space->dim()), hi(space->dim());
    for (std::size_t i = 0; i < space->dim(); ++i) hi[i] = -(lo[i] = -space->bound(i));
    return {lo, hi};
  }
};

class DeCorrector final : public Corrector {
 public:
  explicit DeCorrector(const CorrectorOptions& o) : options_(o) {}

  Correction correct(DiceEnv& env, const CorrectionProblem& p, std::uint64_t seed) const override {
    const ScaledWindow space(env.config(), p.target.size());
    const Eigen::VectorXd x0 = space.point(p.warm);
    const auto n = static_cast<std::size_t>(x0.size());
    const int size = options_.population > 0 ? options_.population : 4 + static_cast<int>(std::floor(3.0 * std::log(static_cast<double>(n))));
    pagmo::problem prob{WindowProblem{&env, &p, &space}};
    const auto pagmo_seed = static_cast<unsigned>(seed & 0xffffffffu);
    pagmo::population pop{prob, 0u, pagmo_seed};
    // Warm start: the policy's actions and a Gaussian cloud of sigma0 around them.
    Rng rng(seed);
    pagmo::vector_double x(n);
    for (int k = 0; k < std::max(size, 5); ++k) {  // pagmo's DE needs at least 5 members
      for (std::size_t i = 0; i < n; ++i) x[i] = space.clip(i, x0[static_cast<Eigen::Index>(i)] + (k == 0 ? 0.0 : options_.sigma0 * rng.normal()));
      pop.push_back(x);
    }
    const double warm_cost = pop.get_f()[0][0];
    const pagmo::de de(static_cast<unsigned>(options_.iterations), 0.8, 0.9, 2u, 0.0, 0.0, pagmo_seed);
    pop = de.evolve(pop);
    std::vector<Action> best = space.actions(pop.champion_x().data());
    return finish(env, p, std::move(best), warm_cost, static_cast<int>(pop.get_problem().get_fevals()));
  }

 private:
  CorrectorOptions options_;
};

}  // namespace

std::unique_ptr<Corrector> make_corrector(std::string_view name, const CorrectorOptions& options) {
  if (name == "cmaes") return std::make_unique<CmaesCorrector>(options);
  if (name == "de") return std::make_unique<DeCorrector>(options);
  throw ConfigError("unknown corrector \"" + std::string(name) + "\"; expected cmaes or de");
}

}  // namespace dicestack
