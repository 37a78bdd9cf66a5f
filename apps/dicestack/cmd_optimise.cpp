// `dicestack optimise`: an open-loop action sequence to the goal stack (paper V-B).
#include <algorithm>
#include <cstdio>

#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "baselines.hpp"

namespace dicestack::cli {
namespace {

int run_optimise(OptimiseCommandOptions opt, Cluster& cluster) {
  check_demo_set_replaceable(opt.out);  // refuse a user's folder before any work
  const WorldConfig world = open_loop_world(opt);
  // CMA-ES evaluates a generation as one batch, which the ranks share; the other methods
  // evaluate one point at a time and run on the root alone.
  const bool shared = opt.optimiser.method == "cmaes";
  if (!shared && !cluster.is_root()) return 0;
  OpenLoopProblem problem(world, opt.settings, opt.threads, shared ? cluster : local_cluster());
  ProgressBar bar;
  const OptimiseResult r = optimise(problem, opt.optimiser, [&](int evaluations, double best) {
    char text[160];
    std::snprintf(text, sizeof text, "%s: %d/%d evaluations, best cost %.4g", opt.optimiser.method.c_str(), evaluations,
                  opt.optimiser.evaluations, best);
    bar.update(static_cast<double>(evaluations) / opt.optimiser.evaluations, text);
  });
  bar.finish();
  if (!cluster.is_root()) return 0;  // the root writes and prints
  // With noise, the first repeat's noise seed.
  const Episode best = replay(problem.world(), problem.actions(r.best.data()), derive_seed(opt.settings.seed, 0), "dicestack optimise");
  const double rate = r.evaluations / std::max(r.seconds, 1e-9);
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& [evals, cost] : r.curve) curve.push_back({evals, cost});
  nlohmann::json j{{"method", opt.optimiser.method},   {"steps", opt.settings.steps},
                   {"evaluations", r.evaluations},      {"seconds", r.seconds},
                   {"evaluations_per_second", rate},    {"best_cost", r.best_cost},
                   {"gravity_scale", opt.gravity_scale}, {"noise", opt.noise}, {"repeats", opt.settings.repeats},
                   {"discount", world.cost.gamma},      {"seed", opt.optimiser.seed}, {"out", opt.out.string()}};
  j.update(outcome_json(best.outcome));
  char line[256];
  std::snprintf(line, sizeof line, "%s: best cost %.4g after %d evaluations in %.1f s (%.0f evaluations/s)\n",
                opt.optimiser.method.c_str(), r.best_cost, r.evaluations, r.seconds, rate);
  return finish_baseline({opt.out, problem.world(), best,
                          "best open-loop sequence of dicestack optimise --method " + opt.optimiser.method,
                          "dicestack optimise --method " + opt.optimiser.method + " --steps " +
                              std::to_string(opt.settings.steps) + " --evaluations " +
                              std::to_string(opt.optimiser.evaluations) + " --seed " + std::to_string(opt.optimiser.seed),
                          "optimise.json", j, "curve", curve},
                         opt.json, line + ("best sequence: " + outcome_text(best.outcome) + " -> " + opt.out.string()));
}

}  // namespace

void add_optimise_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<OptimiseCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "optimise", "Optimise an open-loop action sequence to the goal stack (paper V-B): cmaes, de, basinhop, bayes");
  cmd->add_option("--method", opt->optimiser.method, "cmaes (ours), de (pagmo), basinhop (Metropolis + COBYLA), bayes (GP-EI)")
      ->check(CLI::IsMember(optimiser_names()))
      ->capture_default_str();
  cmd->add_option("--evaluations", opt->optimiser.evaluations, "Budget of evaluations")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--sigma0", opt->optimiser.sigma0, "Initial step in x units ([-1, 1] per action)")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->optimiser.seed, "Seed of the optimiser")->check(seed_check())->capture_default_str();
  add_problem_options(*cmd, *opt);
  cmd->add_option("--out", opt->out, "Folder for the best sequence (a demonstration set) and optimise.json")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] {
    opt->settings.seed = opt->optimiser.seed;
    run_optimise(*opt, cluster);
  });
}

}  // namespace dicestack::cli
