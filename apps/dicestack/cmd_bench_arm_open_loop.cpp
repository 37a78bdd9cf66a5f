// `dicestack bench arm-open-loop`: the open-loop question on the arm. The best fixed joint
// oscillation (CMA-ES over training starts) from the paper's start and from random starts,
// judged on fresh evaluation starts.
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/arm_oscillation.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct ArmOpenLoopOptions {
  WorldOption world;
  std::vector<std::string> starts{"paper", "random"};
  OscillationSearch search;
  int episodes = 100;
  std::vector<std::uint64_t> evaluation_seeds{0, 1};
  bool json = false;
};

struct Judged {
  std::uint64_t seed = 0;
  int realistic = 0, stacked = 0, walls = 0;
  double dice_in_cup = 0.0;
};

Judged judge_pattern(const WorldConfig& world, const JointOscillation& pattern, int episodes, std::uint64_t seed, int threads) {
  std::vector<Outcome> outcomes(static_cast<std::size_t>(episodes));
  EnvPool envs(world, threads);
  parallel_for(outcomes.size(), threads, [&](std::size_t i, int worker) {
    const std::uint64_t s = evaluation_start_seed(seed, i);
    outcomes[i] = run_oscillation(envs.at(worker), pattern, random_start_state(world, s), s).outcome;
  });
  Judged j;
  j.seed = seed;
  for (const Outcome& o : outcomes) {
    j.realistic += o.realistic_success();
    j.stacked += o.stacked;
    j.walls += o.wall_contact;
    j.dice_in_cup += o.dice_in_cup / static_cast<double>(episodes);
  }
  return j;
}

int run_arm_open_loop(const ArmOpenLoopOptions& opt) {
  if (opt.world.embodiment == "cup") throw ConfigError("bench arm-open-loop: the patterns move the arm's joints; drop --embodiment cup");
  WorldConfig base = opt.world.load();
  base.embodiment = Embodiment::arm;
  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& starts : opt.starts) {
    const WorldConfig world = with_starts(base, starts);
    validate(world);
    const auto t0 = std::chrono::steady_clock::now();
    const OscillationResult best = search_oscillation(world, opt.search, [&](int done, double cost) {
      if (!opt.json) std::fprintf(stderr, "\r%s starts: %d evaluations, best cost %.3f", starts.c_str(), done, cost);
    });
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!opt.json) std::fprintf(stderr, "\n");
    std::vector<Judged> judged;
    for (std::uint64_t seed : opt.evaluation_seeds) judged.push_back(judge_pattern(world, best.best, opt.episodes, seed, opt.search.threads));
    if (opt.json) {
      nlohmann::json evaluations = nlohmann::json::array();
      for (const Judged& j : judged)
        evaluations.push_back({{"seed", j.seed}, {"episodes", opt.episodes}, {"realistic_success", j.realistic},
                               {"stacked", j.stacked}, {"wall_contact", j.walls}, {"dice_in_cup", j.dice_in_cup}});
      rows.push_back({{"starts", starts}, {"training_starts", opt.search.starts}, {"evaluations", best.evaluations},
                      {"best_cost", best.best_cost}, {"search_seconds", seconds}, {"pattern", best.best.to_text()},
                      {"judged", evaluations}});
      continue;
    }
    std::printf("From %s starts: CMA-ES, %d evaluations of %d training starts each (seed %llu), %.0f s; mean search cost %.3f\n%s",
                starts.c_str(), best.evaluations, opt.search.starts, static_cast<unsigned long long>(opt.search.seed), seconds,
                best.best_cost, best.best.to_text().c_str());
    std::printf("| evaluation seed | realistic success | stacked (wall allowed) | wall contact | dice in cup |\n"
                "|---:|---:|---:|---:|---:|\n");
    for (const Judged& j : judged)
      std::printf("| %llu | %d / %d | %d | %d | %.2f |\n", static_cast<unsigned long long>(j.seed), j.realistic, opt.episodes,
                  j.stacked, j.walls, j.dice_in_cup);
    std::printf("\n");
  }
  if (opt.json) print_line(rows.dump());
  return 0;
}

}  // namespace

void add_bench_arm_open_loop_command(CLI::App& bench) {
  auto opt = std::make_shared<ArmOpenLoopOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "arm-open-loop", "The best fixed joint oscillation of the arm (CMA-ES), from the paper's start and from random starts, "
                       "judged on fresh starts: the open-loop question on the arm");
  opt->world.add_to(*cmd);
  cmd->add_option("--starts", opt->starts, "Start distributions to search and judge in (paper, random)")
      ->check(CLI::IsMember(start_names()))
      ->capture_default_str();
  cmd->add_option("--training-starts", opt->search.starts, "Training starts each evaluation of a pattern runs")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--evaluations", opt->search.evaluations, "CMA-ES's budget of pattern evaluations")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  cmd->add_option("--sigma0", opt->search.sigma0, "CMA-ES's first step, in search units")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seed", opt->search.seed, "Seed of the training starts and of CMA-ES")->check(seed_check())->capture_default_str();
  cmd->add_option("--episodes", opt->episodes, "Evaluation starts per evaluation seed")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--evaluation-seeds", opt->evaluation_seeds, "Seeds of the evaluation starts (as evaluate --seed)")
      ->check(seed_check())
      ->capture_default_str();
  cmd->add_option("--threads", opt->search.threads, "Threads (0 = all cores); results do not depend on it")
      ->check(threads_check())
      ->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON array");
  cmd->callback([opt] { run_arm_open_loop(*opt); });
}

}  // namespace dicestack::cli
