// `dicestack bench optimise`: evaluations per second of each optimiser against the bare simulator.
#include <algorithm>
#include <cstdio>

#include <chrono>

#include <dicestack/core/rng.hpp>

#include "baselines.hpp"

namespace dicestack::cli {
namespace {

struct BenchOptimiseOptions {
  OptimiseCommandOptions base;
  std::vector<std::string> methods{"cmaes", "de", "basinhop", "bayes"};
  int bayes_evaluations = 200;
  bool json = false;
};

// Evaluations per second of each optimiser against evaluating the same number of random
// sequences with no optimiser at all (simulation and cost only), on the same threads.
int run_bench_optimise(BenchOptimiseOptions opt) {
  const WorldConfig world = open_loop_world(opt.base);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& method : opt.methods) {
    OptimiseOptions o = opt.base.optimiser;
    o.method = method;
    if (method == "bayes") o.evaluations = std::min(o.evaluations, opt.bayes_evaluations);
    OpenLoopProblem problem(world, opt.base.settings, opt.base.threads);
    const OptimiseResult r = optimise(problem, o);
    // Bare: the same evaluations as batches of 64 random sequences (parallel, like CMA-ES's).
    OpenLoopProblem bare(world, opt.base.settings, method == "cmaes" ? opt.base.threads : 1);
    Rng rng(o.seed);
    Eigen::MatrixXd xs(64, static_cast<Eigen::Index>(bare.dim()));
    for (Eigen::Index i = 0; i < xs.size(); ++i) xs.data()[i] = rng.uniform(-1.0, 1.0);
    const auto t0 = std::chrono::steady_clock::now();
    while (bare.evaluations() < r.evaluations) bare.cost_batch(xs);
    const double bare_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double rate = r.evaluations / r.seconds, bare_rate = bare.evaluations() / bare_s;
    rows.push_back({{"method", method}, {"evaluations", r.evaluations}, {"seconds", r.seconds},
                    {"evaluations_per_second", rate}, {"bare_evaluations_per_second", bare_rate},
                    {"threads", method == "cmaes" ? opt.base.threads : 1}, {"best_cost", r.best_cost}});
    if (!opt.json) {
      char line[256];
      std::snprintf(line, sizeof line, "%-9s %6d evaluations %8.2f s  %8.0f eval/s  bare %8.0f eval/s (%s)  ratio %.2f  best cost %.4g",
                    method.c_str(), r.evaluations, r.seconds, rate, bare_rate,
                    method == "cmaes" ? "all threads" : "1 thread", rate / bare_rate, r.best_cost);
      print_line(line);
    }
  }
  if (opt.json) print_line(rows.dump());
  return 0;
}

}  // namespace

void add_bench_optimise_command(CLI::App& bench) {
  auto opt = std::make_shared<BenchOptimiseOptions>();
  opt->base.optimiser.evaluations = 1000;
  CLI::App* cmd = bench.add_subcommand("optimise", "Evaluations per second of each optimiser against the bare simulator");
  cmd->add_option("--methods", opt->methods, "Only these (comma-separated)")->delimiter(',');
  cmd->add_option("--evaluations", opt->base.optimiser.evaluations, "Budget per optimiser")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--bayes-evaluations", opt->bayes_evaluations, "Budget for bayes (O(N^2) per evaluation)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seed", opt->base.optimiser.seed, "Seed")->check(seed_check())->capture_default_str();
  add_problem_options(*cmd, opt->base);
  cmd->add_flag("--json", opt->json, "Print a JSON list");
  cmd->callback([opt] { run_bench_optimise(*opt); });
}

}  // namespace dicestack::cli
