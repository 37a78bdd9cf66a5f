#include <dicestack/core/action_sequence.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Cholesky>
#include <nlopt.hpp>
#include <pagmo/algorithms/de.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

ActionSequenceProblem::ActionSequenceProblem(const WorldConfig& world, int steps, ActionBox box, Cost cost)
    : scale_(world.action.scale), steps_(steps), cost_(std::move(cost)) {
  if (steps < 1) throw ConfigError("an action sequence needs at least 1 step, got " + std::to_string(steps));
  for (std::size_t k = 0; k < kActionDim; ++k)
    half_width_[k] = box == ActionBox::unit ? 1.0 : world.action.limit[k] / world.action.scale[k];
}

double ActionSequenceProblem::bound(std::size_t i) const { return half_width_[i % kActionDim]; }

double ActionSequenceProblem::clip(std::size_t i, double v) const { return std::clamp(v, -bound(i), bound(i)); }

std::vector<Action> ActionSequenceProblem::actions(const double* x) const {
  std::vector<Action> out(static_cast<std::size_t>(steps_));
  for (std::size_t i = 0; i < dim(); ++i) out[i / kActionDim][i % kActionDim] = clip(i, x[i]) * scale_[i % kActionDim];
  return out;
}

Eigen::VectorXd ActionSequenceProblem::point(const std::vector<Action>& actions) const {
  Eigen::VectorXd x(static_cast<Eigen::Index>(dim()));
  for (std::size_t i = 0; i < dim(); ++i)
    x[static_cast<Eigen::Index>(i)] = clip(i, actions[i / kActionDim][i % kActionDim] / scale_[i % kActionDim]);
  return x;
}

DiceEnv& SequenceEvaluator::first() { return env_ ? *env_ : pool_->at(0); }

double SequenceEvaluator::cost(const ActionSequenceProblem& problem, const double* x) {
  ++evaluations_;
  return problem.cost(first(), x);
}

std::vector<double> SequenceEvaluator::costs(const ActionSequenceProblem& problem, const Eigen::MatrixXd& xs) {
  const auto row_cost = [&](std::size_t i, DiceEnv& env) {
    const Eigen::VectorXd row = xs.row(static_cast<Eigen::Index>(i)).transpose();
    return problem.cost(env, row.data());
  };
  const auto n = static_cast<std::size_t>(xs.rows());
  std::vector<double> out(n);
  if (pool_) {
    out = distributed_map<double>(
        *cluster_, n, threads_, [&](std::size_t i, int w) { return row_cost(i, pool_->at(w)); },
        [](const double& v) { return Packer().put(v).take(); }, [](std::string_view b) { return Unpacker(b, "cost").get<double>(); });
  } else {
    for (std::size_t i = 0; i < n; ++i) out[i] = row_cost(i, *env_);
  }
  evaluations_ += static_cast<int>(n);
  return out;
}

namespace {

// One search: the problem, where it evaluates, its budget, and the best point and curve so far
// (kept alike for every method).
class Search {
 public:
  Search(const ActionSequenceProblem& p, SequenceEvaluator& evaluator, const MinimiseOptions& o,
         const std::function<void(int, double)>& progress)
      : problem(p), options(o), evaluator_(evaluator), start_(evaluator.evaluations()), progress_(progress) {
    result_.best = x0();
    result_.best_cost = std::numeric_limits<double>::infinity();
  }

  const ActionSequenceProblem& problem;
  const MinimiseOptions& options;

  Eigen::Index n() const { return static_cast<Eigen::Index>(problem.dim()); }
  /// The default population: pycma's 4 + floor(3 ln n).
  int default_population() const { return 4 + static_cast<int>(std::floor(3.0 * std::log(static_cast<double>(problem.dim())))); }
  /// The budget in evaluations of the methods without generations.
  int budget() const {
    if (options.evaluations > 0) return options.evaluations;
    return options.iterations * (options.population > 0 ? options.population : default_population());
  }
  int used() const { return evaluator_.evaluations() - start_; }
  Eigen::VectorXd x0() const {
    Eigen::VectorXd x = options.x0 ? *options.x0 : Eigen::VectorXd::Zero(n());
    for (Eigen::Index i = 0; i < x.size(); ++i) x[i] = problem.clip(static_cast<std::size_t>(i), x[i]);
    return x;
  }

  double cost(const double* x) {
    const double v = evaluator_.cost(problem, x);
    offer(x, v);
    return v;
  }
  /// Costs of every row; the rows offered clipped (the point whose cost it is).
  std::vector<double> costs(const Eigen::MatrixXd& xs) {
    const std::vector<double> values = evaluator_.costs(problem, xs);
    for (Eigen::Index r = 0; r < xs.rows(); ++r) {
      Eigen::VectorXd row = xs.row(r).transpose();
      for (Eigen::Index i = 0; i < row.size(); ++i) row[i] = problem.clip(static_cast<std::size_t>(i), row[i]);
      offer(row.data(), values[static_cast<std::size_t>(r)]);
    }
    return values;
  }
  void offer(const double* x, double value) {
    if (value < result_.best_cost) {
      result_.best_cost = value;
      result_.best = Eigen::Map<const Eigen::VectorXd>(x, n());
    }
  }
  void generation() {
    result_.curve.emplace_back(used(), result_.best_cost);
    if (progress_) progress_(used(), result_.best_cost);
  }
  MinimiseResult take() {
    result_.evaluations = used();
    return std::move(result_);
  }

 private:
  SequenceEvaluator& evaluator_;
  int start_;
  const std::function<void(int, double)>& progress_;
  MinimiseResult result_;
};

void run_cmaes(Search& s) {
  CmaesOptions co;
  co.population = s.options.population;
  co.sigma0 = s.options.sigma0;
  co.max_evaluations = s.options.evaluations;
  co.max_iterations = s.options.evaluations > 0 ? 0 : s.options.iterations;
  co.seed = s.options.seed;
  Cmaes es(s.x0(), co);
  while (!es.done()) {
    // Candidates are clipped to the box when evaluated; CMA-ES sees the clipped point's value.
    const Eigen::MatrixXd& x = es.ask();
    es.tell(s.costs(x));
    s.generation();
  }
}

// pagmo's view of the problem: one candidate at a time (pagmo has no batch evaluation).
struct PagmoProblem {
  Search* search = nullptr;
  pagmo::vector_double fitness(const pagmo::vector_double& x) const { return {search->cost(x.data())}; }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    const std::size_t n = search->problem.dim();
    pagmo::vector_double lo(n), hi(n);
    for (std::size_t i = 0; i < n; ++i) hi[i] = -(lo[i] = -search->problem.bound(i));
    return {lo, hi};
  }
};

// pagmo's DE (DE/rand/1/exp), one generation at a time, for the curve and the budget.
void run_de(Search& s) {
  const MinimiseOptions& o = s.options;
  const int size = std::max(o.population > 0 ? o.population : s.default_population(), 5);  // pagmo's DE needs 5
  const auto seed = static_cast<unsigned>(o.seed & 0xffffffffu);
  pagmo::problem prob{PagmoProblem{&s}};
  pagmo::population pop{prob, o.x0 ? 0u : static_cast<unsigned>(size), seed};
  if (o.x0) {  // x0 and a Gaussian cloud of sigma0 around it
    const Eigen::VectorXd x0 = s.x0();
    Rng rng(o.seed);
    pagmo::vector_double x(static_cast<std::size_t>(x0.size()));
    for (int k = 0; k < size; ++k) {
      for (std::size_t i = 0; i < x.size(); ++i)
        x[i] = s.problem.clip(i, x0[static_cast<Eigen::Index>(i)] + (k == 0 ? 0.0 : o.sigma0 * rng.normal()));
      pop.push_back(x);
    }
  }
  s.generation();
  const pagmo::de de(1u, 0.8, 0.9, 2u, 0.0, 0.0, seed);
  for (int g = 0; o.evaluations > 0 ? s.used() + size <= o.evaluations : g < o.iterations; ++g) {
    pop = de.evolve(pop);  // the population and pagmo's random stream carry over
    s.generation();
  }
}

// scipy.optimize.basinhopping's loop: perturb uniformly by +-0.5, minimise locally, accept by the
// Metropolis rule at temperature 1. Local minimiser: NLopt's COBYLA (derivative-free; the cost
// is a simulation).
void run_basinhop(Search& s) {
  const std::size_t n = s.problem.dim();
  const int budget = s.budget();
  const int local_budget = static_cast<int>(std::max<std::size_t>(4 * n, 100));
  Rng rng(s.options.seed);
  auto objective = [](const std::vector<double>& x, std::vector<double>&, void* data) {
    return static_cast<Search*>(data)->cost(x.data());
  };
  std::vector<double> lower(n), upper(n);
  for (std::size_t i = 0; i < n; ++i) upper[i] = -(lower[i] = -s.problem.bound(i));
  auto local = [&](std::vector<double>& x) {
    const int left = budget - s.used();
    if (left <= 0) return std::numeric_limits<double>::infinity();
    nlopt::opt opt(nlopt::LN_COBYLA, static_cast<unsigned>(n));
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_min_objective(objective, &s);
    opt.set_maxeval(std::min(local_budget, left));
    opt.set_initial_step(s.options.sigma0);
    double value = std::numeric_limits<double>::infinity();
    try {
      opt.optimize(x, value);
    } catch (const std::exception&) {  // roundoff or forced stop: keep what it reached
      value = s.cost(x.data());
    }
    s.generation();
    return value;
  };
  const Eigen::VectorXd start = s.x0();
  std::vector<double> x(start.data(), start.data() + start.size());
  double fx = local(x);
  const double step = 0.5, temperature = 1.0;
  while (s.used() < budget) {
    std::vector<double> y = x;
    for (std::size_t i = 0; i < n; ++i) y[i] = s.problem.clip(i, y[i] + rng.uniform(-step, step));
    const double fy = local(y);
    if (fy < fx || rng.uniform() < std::exp(-(fy - fx) / temperature)) {
      x = std::move(y);
      fx = fy;
    }
  }
}

// Bayesian optimisation: a Gaussian process (squared-exponential kernel, length scale
// 0.5 sqrt(n), standardised values) with expected improvement maximised over random and
// best-centred candidates. The kernel matrix grows by a row per point; its Cholesky factor is
// recomputed, O(N^3) per evaluation in the number of points N: slow, as the paper found.
void run_bayes(Search& s) {
  const Eigen::Index n = s.n();
  const int budget = s.budget();
  const double length = 0.5 * std::sqrt(static_cast<double>(n)), jitter = 1e-6;
  const int initial = std::min(10, budget), candidates = 256;
  Rng rng(s.options.seed);
  const Eigen::VectorXd x0 = s.x0();
  // Exploration: uniform in the box, or, for a search started at x0 (a correction of a
  // policy's actions), a Gaussian cloud of sigma0 around x0 (the box is then far wider than the
  // region worth modelling).
  auto uniform = [&](Eigen::Index j) {
    const auto i = static_cast<std::size_t>(j);
    if (s.options.x0) return s.problem.clip(i, x0[j] + s.options.sigma0 * rng.normal());
    return rng.uniform(-s.problem.bound(i), s.problem.bound(i));
  };
  Eigen::MatrixXd xs(0, n);
  std::vector<double> ys;
  auto kernel = [&](const auto& a, const auto& b) { return std::exp(-(a - b).squaredNorm() / (2.0 * length * length)); };
  Eigen::MatrixXd k(0, 0);  // the kernel matrix of the points so far, grown by one row and column per point
  auto add = [&](const Eigen::VectorXd& x) {
    const double y = s.cost(x.data());
    const Eigen::Index m = xs.rows();
    xs.conservativeResize(m + 1, n);
    xs.row(m) = x.transpose();
    k.conservativeResize(m + 1, m + 1);
    for (Eigen::Index a = 0; a < m; ++a) k(a, m) = k(m, a) = kernel(xs.row(a), xs.row(m));
    k(m, m) = 1.0 + jitter;
    ys.push_back(y);
  };
  for (int i = 0; i < initial; ++i) {
    Eigen::VectorXd x(n);
    for (Eigen::Index j = 0; j < n; ++j) x[j] = i == 0 ? x0[j] : uniform(j);
    add(x);
  }
  s.generation();
  while (s.used() < budget) {
    const Eigen::Index m = xs.rows();
    const Eigen::Map<const Eigen::VectorXd> y(ys.data(), m);
    const double mean = y.mean(), sd = std::max(std::sqrt((y.array() - mean).square().mean()), 1e-12);
    const Eigen::VectorXd z = (y.array() - mean) / sd;
    const Eigen::LLT<Eigen::MatrixXd> llt(k);
    const Eigen::VectorXd alpha = llt.solve(z);
    const double best = z.minCoeff();
    Eigen::Index best_row = 0;
    z.minCoeff(&best_row);
    Eigen::VectorXd chosen = xs.row(best_row).transpose();
    double chosen_ei = -1.0;
    for (int c = 0; c < candidates; ++c) {
      Eigen::VectorXd x(n);
      for (Eigen::Index j = 0; j < n; ++j)
        x[j] = c % 2 ? uniform(j) : s.problem.clip(static_cast<std::size_t>(j), xs(best_row, j) + 0.1 * rng.normal());
      Eigen::VectorXd kx(m);
      for (Eigen::Index a = 0; a < m; ++a) kx[a] = kernel(xs.row(a), x.transpose());
      const double mu = kx.dot(alpha);
      const double var = std::max(1.0 - kx.dot(llt.solve(kx)), 1e-12), sd_x = std::sqrt(var);
      const double u = (best - mu) / sd_x;
      const double ei = sd_x * (u * 0.5 * std::erfc(-u / std::numbers::sqrt2) +
                                std::exp(-0.5 * u * u) / std::sqrt(2.0 * std::numbers::pi));
      if (ei > chosen_ei) {
        chosen_ei = ei;
        chosen = x;
      }
    }
    add(chosen);
    s.generation();
  }
}

}  // namespace

std::vector<std::string> minimiser_names() { return {"cmaes", "de", "basinhop", "bayes"}; }

MinimiseResult minimise(const ActionSequenceProblem& problem, SequenceEvaluator& evaluator, const MinimiseOptions& o,
                        const std::function<void(int, double)>& progress) {
  if (o.evaluations < 0 || o.iterations < 0 || (o.evaluations == 0 && o.iterations == 0))
    throw ConfigError("minimise: the budget must be at least 1 evaluation or 1 iteration");
  if (!(o.sigma0 > 0.0)) throw ConfigError("minimise: sigma0 must be positive");
  if (o.population < 0) throw ConfigError("minimise: the population must not be negative");
  if (o.x0 && static_cast<std::size_t>(o.x0->size()) != problem.dim())
    throw ConfigError("minimise: x0 has " + std::to_string(o.x0->size()) + " coordinates, the problem " +
                      std::to_string(problem.dim()));
  Search s(problem, evaluator, o, progress);
  if (o.method == "cmaes") run_cmaes(s);
  else if (o.method == "de") run_de(s);
  else if (o.method == "basinhop") run_basinhop(s);
  else if (o.method == "bayes") run_bayes(s);
  else throw ConfigError("unknown optimiser \"" + o.method + "\"; expected cmaes, de, basinhop or bayes");
  return s.take();
}

}  // namespace dicestack
