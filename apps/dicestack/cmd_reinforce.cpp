// `dicestack reinforce`: REINFORCE from the paper's start (paper V-C).
#include <algorithm>
#include <cstdio>

#include <dicestack/core/reinforce.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "baselines.hpp"

namespace dicestack::cli {
namespace {

struct ReinforceCommandOptions {
  WorldOption world;
  ReinforceOptions reinforce;
  std::filesystem::path out;
  bool json = false;
};

int run_reinforce(const ReinforceCommandOptions& opt, Cluster& cluster) {
  check_demo_set_replaceable(opt.out);
  const WorldConfig world = opt.world.load();
  ReinforceOptions options = opt.reinforce;
  options.cluster = &cluster;  // the ranks share each batch's episodes
  ProgressBar bar;
  const ReinforceResult r = reinforce(world, options, [&](const ReinforcePoint& p) {
    char text[160];
    std::snprintf(text, sizeof text, "reinforce: iteration %d/%d, mean return %.3g, greedy cost %.4g", p.iteration,
                  opt.reinforce.iterations, p.mean_return, p.greedy_cost);
    bar.update(static_cast<double>(p.iteration) / opt.reinforce.iterations, text);
  });
  bar.finish();
  if (!cluster.is_root()) return 0;  // the root writes and prints
  WorldConfig played = world;
  played.episode.max_steps = std::max(played.episode.max_steps, opt.reinforce.steps);
  const Episode greedy = replay(played, r.greedy_actions, 0, "dicestack reinforce");
  nlohmann::json curve = nlohmann::json::array();
  for (const auto& p : r.curve) curve.push_back({p.iteration, p.mean_return, p.greedy_cost});
  nlohmann::json j{{"iterations", opt.reinforce.iterations}, {"episodes", opt.reinforce.iterations * opt.reinforce.batch},
                   {"seconds", r.seconds},  {"final_greedy_cost", r.curve.back().greedy_cost},
                   {"final_mean_return", r.curve.back().mean_return}, {"seed", opt.reinforce.seed}, {"out", opt.out.string()}};
  j.update(outcome_json(greedy.outcome));
  char line[256];
  std::snprintf(line, sizeof line, "reinforce: %d episodes in %.1f s; mean return %.4g -> %.4g, greedy cost %.4g -> %.4g\n",
                opt.reinforce.iterations * opt.reinforce.batch, r.seconds, r.curve.front().mean_return, r.curve.back().mean_return,
                r.curve.front().greedy_cost, r.curve.back().greedy_cost);
  return finish_baseline({opt.out, played, greedy, "the mean actions of the policy learned by dicestack reinforce",
                          "dicestack reinforce --iterations " + std::to_string(opt.reinforce.iterations) + " --batch " +
                              std::to_string(opt.reinforce.batch) + " --steps " + std::to_string(opt.reinforce.steps) +
                              " --seed " + std::to_string(opt.reinforce.seed),
                          "reinforce.json", j, "curve (iteration, mean return, greedy cost)", curve},
                         opt.json, line + ("greedy policy: " + outcome_text(greedy.outcome) + " -> " + opt.out.string()));
}

}  // namespace

void add_reinforce_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<ReinforceCommandOptions>();
  auto& r = opt->reinforce;
  CLI::App* cmd = app.add_subcommand("reinforce", "REINFORCE from the paper's start (paper V-C): a Gaussian policy on a 3-layer network");
  opt->world.add_to(*cmd);
  cmd->add_option("--iterations", r.iterations, "Policy updates")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--batch", r.batch, "Episodes per update")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--steps", r.steps, "Control steps per episode")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--hidden", r.hidden, "Units per hidden layer")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--sigma", r.sigma, "Exploration std, scaled action units")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--discount", r.discount, "Return discount")->check(CLI::Range(0.0, 1.0))->capture_default_str();
  cmd->add_option("--baseline-decay", r.baseline_decay, "Moving-average factor of the per-timestep baseline")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--learning-rate", r.learning_rate, "Adam step size")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", r.seed, "Seed")->check(seed_check())->capture_default_str();
  cmd->add_option("--threads", r.threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--out", opt->out, "Folder for the greedy episode (a demonstration set) and reinforce.json")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] { run_reinforce(*opt, cluster); });
}

}  // namespace dicestack::cli
