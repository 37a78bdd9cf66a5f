// `dicestack rrt`: RRT from the paper's start (paper V-D).
#include <algorithm>
#include <cstdio>

#include <dicestack/core/rrt.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "baselines.hpp"

namespace dicestack::cli {
namespace {

struct RrtCommandOptions {
  WorldOption world;
  RrtOptions rrt;
  std::filesystem::path out;
  bool json = false;
};

int run_rrt(const RrtCommandOptions& opt, Cluster& cluster) {
  check_demo_set_replaceable(opt.out);
  const WorldConfig world = opt.world.load();
  RrtOptions options = opt.rrt;
  options.cluster = &cluster;  // the ranks share each extension's CMA-ES generations (the command's method)
  ProgressBar bar;
  const RrtResult r = rrt(world, options, [&](int nodes, double best) {
    char text[160];
    std::snprintf(text, sizeof text, "rrt: %d/%d nodes, nearest to the goal %.4g", nodes, opt.rrt.nodes, best);
    bar.update(static_cast<double>(nodes) / std::max(1, opt.rrt.nodes), text);
  });
  bar.finish();
  if (!cluster.is_root()) return 0;  // the root writes and prints
  WorldConfig played = world;
  played.episode.max_steps = std::max(played.episode.max_steps, static_cast<int>(r.actions.size()));
  // When no node got nearer the goal than the start, there is no path: the set has no episode.
  const Episode path = r.actions.empty() ? Episode{} : replay(played, r.actions, 0, "dicestack rrt");
  const double rate = static_cast<double>(r.simulated_steps) / std::max(r.seconds, 1e-9);
  nlohmann::json j{{"nodes", r.nodes},          {"simulated_steps", r.simulated_steps}, {"seconds", r.seconds},
                   {"steps_per_second", rate},  {"best_distance", r.best_distance},   {"path_steps", r.actions.size()},
                   {"seed", opt.rrt.seed},      {"out", opt.out.string()}};
  j.update(outcome_json(path.outcome));
  char line[256];
  std::snprintf(line, sizeof line, "rrt: %d nodes, %lld simulated steps in %.1f s (%.0f steps/s); nearest to the goal %.4g after %zu steps\n",
                r.nodes, r.simulated_steps, r.seconds, rate, r.best_distance, r.actions.size());
  return finish_baseline({opt.out, played, r.actions.empty() ? std::nullopt : std::optional<Episode>(path),
                          r.actions.empty() ? "dicestack rrt found no node nearer the goal than the start: no path"
                                            : "the path to the node nearest the goal in the tree of dicestack rrt",
                          "dicestack rrt --nodes " + std::to_string(opt.rrt.nodes) + " --extend-steps " +
                              std::to_string(opt.rrt.extend_steps) + " --seed " + std::to_string(opt.rrt.seed),
                          "rrt.json", j, "", nullptr},
                         opt.json, line + ("path (none if no node got nearer than the start): " + outcome_text(path.outcome) +
                                           " -> " + opt.out.string()));
}

}  // namespace

void add_rrt_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<RrtCommandOptions>();
  auto& r = opt->rrt;
  CLI::App* cmd = app.add_subcommand("rrt", "RRT from the paper's start (paper V-D): extensions optimise a few steps of actions");
  opt->world.add_to(*cmd);
  cmd->add_option("--nodes", r.nodes, "Extensions")->check(CLI::NonNegativeNumber)->capture_default_str();
  cmd->add_option("--extend-steps", r.extend_steps, "Control steps per extension")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--extend-iterations", r.extend_iterations, "CMA-ES generations per extension")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--goal-bias", r.goal_bias, "Probability of growing towards the goal")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  cmd->add_option("--max-depth", r.max_depth_steps, "Nodes this many steps deep are not extended")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", r.seed, "Seed")->check(seed_check())->capture_default_str();
  cmd->add_option("--threads", r.threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--out", opt->out, "Folder for the best path (a demonstration set) and rrt.json")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] { run_rrt(*opt, cluster); });
}

}  // namespace dicestack::cli
