#include <dicestack/core/open_loop.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Cholesky>
#include <nlopt.hpp>
#include <pagmo/algorithms/de.hpp>
#include <pagmo/population.hpp>
#include <pagmo/problem.hpp>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

OpenLoopProblem::OpenLoopProblem(const WorldConfig& world, const OpenLoopSettings& settings, int threads, Cluster& cluster)
    : world_(world), settings_(settings), threads_(threads), cluster_(&cluster) {
  validate(world_);
  if (settings.steps < 1) throw ConfigError("open-loop steps must be at least 1, got " + std::to_string(settings.steps));
  if (settings.repeats < 1) throw ConfigError("open-loop repeats must be at least 1, got " + std::to_string(settings.repeats));
  world_.episode.max_steps = std::max(world_.episode.max_steps, settings.steps);
  start_ = paper_start_state(world_);
  goal_ = goal_state(world_);
  envs_.emplace(world_, threads);
}

std::vector<Action> OpenLoopProblem::actions(const double* x) const {
  std::vector<Action> out(static_cast<std::size_t>(settings_.steps));
  for (std::size_t i = 0; i < dim(); ++i)
    out[i / kActionDim][i % kActionDim] = std::clamp(x[i], -1.0, 1.0) * world_.action.scale[i % kActionDim];
  return out;
}

double OpenLoopProblem::run(DiceEnv& env, const double* x) const {
  const std::vector<Action> a = actions(x);
  std::vector<State> trajectory(a.size());
  double total = 0.0;
  for (int r = 0; r < settings_.repeats; ++r) {
    env.reset_to(start_, derive_seed(settings_.seed, static_cast<std::uint64_t>(r)));
    for (std::size_t t = 0; t < a.size(); ++t) trajectory[t] = env.step(a[t]).observation;
    total += discounted_cost(trajectory, goal_, world_.cost);
  }
  return total / settings_.repeats;
}

double OpenLoopProblem::cost(const double* x) {
  ++evaluations_;
  return run(envs_->at(0), x);
}

std::vector<double> OpenLoopProblem::cost_batch(const Eigen::MatrixXd& xs) {
  const std::vector<double> out = distributed_map<double>(
      *cluster_, static_cast<std::size_t>(xs.rows()), threads_,
      [&](std::size_t i, int w) {
        const Eigen::VectorXd row = xs.row(static_cast<Eigen::Index>(i)).transpose();
        return run(envs_->at(w), row.data());
      },
      [](const double& v) { return Packer().put(v).take(); }, [](std::string_view b) { return Unpacker(b, "cost").get<double>(); });
  evaluations_ += static_cast<int>(out.size());
  return out;
}

namespace {

// Tracks the best point and the curve for every method alike.
class Recorder {
 public:
  Recorder(std::size_t n, const std::function<void(int, double)>& progress) : progress_(progress) { result_.best.assign(n, 0.0); result_.best_cost = std::numeric_limits<double>::infinity(); }
  void offer(const double* x, double value) {
    if (value < result_.best_cost) {
      result_.best_cost = value;
      result_.best.assign(x, x + result_.best.size());
    }
  }
  void generation(int evaluations) {
    result_.curve.emplace_back(evaluations, result_.best_cost);
    if (progress_) progress_(evaluations, result_.best_cost);
  }
  OptimiseResult take() { return std::move(result_); }

 private:
  OptimiseResult result_;
  const std::function<void(int, double)>& progress_;
};

void run_cmaes(OpenLoopProblem& p, const OptimiseOptions& o, Recorder& rec) {
  CmaesOptions co;
  co.sigma0 = o.sigma0;
  co.max_evaluations = o.evaluations;
  co.seed = o.seed;
  Cmaes es(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(p.dim())), co);
  while (!es.done()) {
    // Candidates are clipped to the box when evaluated; CMA-ES sees the clipped point's value.
    const Eigen::MatrixXd& x = es.ask();
    const std::vector<double> values = p.cost_batch(x);
    for (Eigen::Index r = 0; r < x.rows(); ++r) {
      Eigen::VectorXd row = x.row(r).transpose().cwiseMax(-1.0).cwiseMin(1.0);
      rec.offer(row.data(), values[static_cast<std::size_t>(r)]);
    }
    es.tell(values);
    rec.generation(p.evaluations());
  }
}

struct PagmoProblem {
  OpenLoopProblem* problem = nullptr;
  pagmo::vector_double fitness(const pagmo::vector_double& x) const { return {problem->cost(x.data())}; }
  std::pair<pagmo::vector_double, pagmo::vector_double> get_bounds() const {
    return {pagmo::vector_double(problem->dim(), -1.0), pagmo::vector_double(problem->dim(), 1.0)};
  }
};

// pagmo's DE evaluates one candidate at a time (it has no batch evaluation): one core.
void run_de(OpenLoopProblem& p, const OptimiseOptions& o, Recorder& rec) {
  const auto n = static_cast<double>(p.dim());
  const auto size = static_cast<unsigned>(std::max(5.0, 4.0 + std::floor(3.0 * std::log(n))));
  const auto seed = static_cast<unsigned>(o.seed & 0xffffffffu);
  pagmo::problem prob{PagmoProblem{&p}};
  pagmo::population pop{prob, size, seed};
  const pagmo::de de(1u, 0.8, 0.9, 2u, 0.0, 0.0, seed);
  rec.offer(pop.champion_x().data(), pop.champion_f()[0]);
  rec.generation(p.evaluations());
  while (p.evaluations() + static_cast<int>(size) <= o.evaluations) {
    pop = de.evolve(pop);  // one generation at a time, for the curve; the population carries over
    rec.offer(pop.champion_x().data(), pop.champion_f()[0]);
    rec.generation(p.evaluations());
  }
}

// scipy.optimize.basinhopping's loop: perturb uniformly by +-step, minimise locally, accept by
// the Metropolis rule at temperature 1. Local minimiser: NLopt's COBYLA (derivative-free; the
// cost is a simulation).
void run_basinhop(OpenLoopProblem& p, const OptimiseOptions& o, Recorder& rec) {
  const std::size_t n = p.dim();
  const int local_budget = static_cast<int>(std::max<std::size_t>(4 * n, 100));
  Rng rng(o.seed);
  struct Context {
    OpenLoopProblem* p;
    Recorder* rec;
  } ctx{&p, &rec};
  auto objective = [](const std::vector<double>& x, std::vector<double>&, void* data) {
    auto* c = static_cast<Context*>(data);
    const double v = c->p->cost(x.data());
    c->rec->offer(x.data(), v);
    return v;
  };
  auto local = [&](std::vector<double>& x) {
    const int left = o.evaluations - p.evaluations();
    if (left <= 0) return std::numeric_limits<double>::infinity();
    nlopt::opt opt(nlopt::LN_COBYLA, static_cast<unsigned>(n));
    opt.set_lower_bounds(-1.0);
    opt.set_upper_bounds(1.0);
    opt.set_min_objective(objective, &ctx);
    opt.set_maxeval(std::min(local_budget, left));
    opt.set_initial_step(o.sigma0);
    double value = std::numeric_limits<double>::infinity();
    try {
      opt.optimize(x, value);
    } catch (const std::exception&) {  // roundoff or forced stop: keep what it reached
      value = p.cost(x.data());
    }
    rec.generation(p.evaluations());
    return value;
  };
  std::vector<double> x(n, 0.0);
  double fx = local(x);
  const double step = 0.5, temperature = 1.0;
  while (p.evaluations() < o.evaluations) {
    std::vector<double> y = x;
    for (double& v : y) v = std::clamp(v + rng.uniform(-step, step), -1.0, 1.0);
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
void run_bayes(OpenLoopProblem& p, const OptimiseOptions& o, Recorder& rec) {
  const auto n = static_cast<Eigen::Index>(p.dim());
  const double length = 0.5 * std::sqrt(static_cast<double>(n)), jitter = 1e-6;
  const int initial = std::min(10, o.evaluations), candidates = 256;
  Rng rng(o.seed);
  Eigen::MatrixXd xs(0, n);
  std::vector<double> ys;
  auto kernel = [&](const auto& a, const auto& b) { return std::exp(-(a - b).squaredNorm() / (2.0 * length * length)); };
  Eigen::MatrixXd k(0, 0);  // the kernel matrix of the points so far, grown by one row and column per point
  auto add = [&](const Eigen::VectorXd& x, double y) {
    const Eigen::Index m = xs.rows();
    xs.conservativeResize(m + 1, n);
    xs.row(m) = x.transpose();
    k.conservativeResize(m + 1, m + 1);
    for (Eigen::Index a = 0; a < m; ++a) k(a, m) = k(m, a) = kernel(xs.row(a), xs.row(m));
    k(m, m) = 1.0 + jitter;
    ys.push_back(y);
    rec.offer(x.data(), y);
  };
  for (int i = 0; i < initial; ++i) {
    Eigen::VectorXd x(n);
    for (Eigen::Index j = 0; j < n; ++j) x[j] = i == 0 ? 0.0 : rng.uniform(-1.0, 1.0);
    add(x, p.cost(x.data()));
  }
  rec.generation(p.evaluations());
  while (p.evaluations() < o.evaluations) {
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
        x[j] = c % 2 ? rng.uniform(-1.0, 1.0) : std::clamp(xs(best_row, j) + 0.1 * rng.normal(), -1.0, 1.0);
      Eigen::VectorXd kx(m);
      for (Eigen::Index a = 0; a < m; ++a) kx[a] = kernel(xs.row(a), x.transpose());
      const double mu = kx.dot(alpha);
      const double var = std::max(1.0 - kx.dot(llt.solve(kx)), 1e-12), s = std::sqrt(var);
      const double u = (best - mu) / s;
      const double ei = s * (u * 0.5 * std::erfc(-u / std::numbers::sqrt2) + std::exp(-0.5 * u * u) / std::sqrt(2.0 * std::numbers::pi));
      if (ei > chosen_ei) {
        chosen_ei = ei;
        chosen = x;
      }
    }
    add(chosen, p.cost(chosen.data()));
    rec.generation(p.evaluations());
  }
}

}  // namespace

std::vector<std::string> optimiser_names() { return {"cmaes", "de", "basinhop", "bayes"}; }

OptimiseResult optimise(OpenLoopProblem& problem, const OptimiseOptions& o, const std::function<void(int, double)>& progress) {
  if (o.evaluations < 1) throw ConfigError("optimise: the budget must be at least 1 evaluation");
  if (!(o.sigma0 > 0.0)) throw ConfigError("optimise: sigma0 must be positive");
  const auto t0 = std::chrono::steady_clock::now();
  Recorder rec(problem.dim(), progress);
  if (o.method == "cmaes") run_cmaes(problem, o, rec);
  else if (o.method == "de") run_de(problem, o, rec);
  else if (o.method == "basinhop") run_basinhop(problem, o, rec);
  else if (o.method == "bayes") run_bayes(problem, o, rec);
  else throw ConfigError("unknown optimiser \"" + o.method + "\"; expected cmaes, de, basinhop or bayes");
  OptimiseResult r = rec.take();
  r.evaluations = problem.evaluations();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace dicestack
