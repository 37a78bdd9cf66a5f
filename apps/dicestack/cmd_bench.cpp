// `dicestack bench ...`: figures the issues ask for, measured in this process (Release builds).
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/bare_box2d.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/world.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct SimOptions {
  WorldOption world;
  int threads = 0;
  int episodes = 200;
  int steps = 100;
  int repeats = 5;
  std::uint64_t seed = 1;
  bool sleep = false;
  bool json = false;
};

// Runs the benchmark's episodes through DiceEnv (the framework) on `threads` threads and
// records each episode's outcome. Actions match bare_box2d_seconds draw for draw.
double framework_seconds(const WorldConfig& config, const SimOptions& opt, int threads, std::vector<Outcome>* outcomes) {
  const State start = paper_start_state(config);
  EnvPool envs(config, threads);
  if (outcomes) outcomes->assign(static_cast<std::size_t>(opt.episodes), Outcome{});
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(static_cast<std::size_t>(opt.episodes), threads, [&](std::size_t e, int worker) {
    DiceEnv& env = envs.at(worker);
    env.reset_to(start);
    Rng rng(derive_seed(opt.seed, e));
    for (int t = 0; t < opt.steps; ++t) {
      Action a;
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] = rng.uniform(-1.0, 1.0) * config.action.scale[k];
      env.step(a);
    }
    if (outcomes) (*outcomes)[e] = env.outcome();
  });
  return seconds_since(t0);
}

// The bare loop on `threads` threads, each running its share of the episodes.
double bare_parallel_seconds(const WorldConfig& config, const SimOptions& opt, int threads) {
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(static_cast<std::size_t>(threads), threads, [&](std::size_t i, int) {
    bare_box2d_seconds(config, opt.episodes / threads, opt.steps, derive_seed(opt.seed, i));
  });
  return seconds_since(t0);
}

int run_sim(const SimOptions& opt) {
  const WorldConfig config = opt.world.load();
  const int threads = resolve_threads(opt.threads);
  const double n = opt.episodes;
  std::vector<double> bare, bare_multi, single, multi, sleepy;
  std::vector<Outcome> awake_outcomes, sleep_outcomes;
  WorldConfig sleep_config = config;
  sleep_config.physics.allow_sleep = true;
  for (int r = 0; r < opt.repeats; ++r) {
    bare.push_back(n / bare_box2d_seconds(config, opt.episodes, opt.steps, opt.seed));
    single.push_back(n / framework_seconds(config, opt, 1, &awake_outcomes));
    multi.push_back(n / framework_seconds(config, opt, threads, nullptr));
    bare_multi.push_back((opt.episodes / threads) * threads / bare_parallel_seconds(config, opt, threads));
    if (opt.sleep) sleepy.push_back(n / framework_seconds(sleep_config, opt, 1, &sleep_outcomes));
  }
  const double eps = median(single), eps_threads = median(multi), eps_bare = median(bare);
  const double eps_bare_threads = median(bare_multi);
  const double physics_per_episode = static_cast<double>(opt.steps) * config.physics.substeps;
  int same_outcome = 0;
  for (std::size_t e = 0; e < sleep_outcomes.size(); ++e) {
    const Outcome &a = awake_outcomes[e], &b = sleep_outcomes[e];
    same_outcome += a.dice_in_cup == b.dice_in_cup && a.stacked == b.stacked && a.wall_contact == b.wall_contact;
  }
  if (opt.json) {
    nlohmann::json j{{"episodes_per_second", eps},
                     {"episodes_per_second_threads", eps_threads},
                     {"threads", threads},
                     {"bare_episodes_per_second", eps_bare},
                     {"bare_episodes_per_second_threads", eps_bare_threads},
                     {"ratio_to_bare", eps / eps_bare},
                     {"physics_steps_per_second", eps * physics_per_episode},
                     {"physics_steps_per_second_threads", eps_threads * physics_per_episode},
                     {"scaling", eps_threads / eps},
                     {"episodes", opt.episodes},
                     {"steps", opt.steps},
                     {"repeats", opt.repeats}};
    if (opt.sleep) {
      j["sleep_episodes_per_second"] = median(sleepy);
      j["sleep_same_outcome_fraction"] = static_cast<double>(same_outcome) / n;
    }
    print_line(j.dump());
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "bench sim: %d episodes x %d control steps (%d substeps, %d velocity iterations), random actions;\n"
                "medians of %d runs\n"
                "  bare Box2D loop, 1 thread : %8.1f episodes/s  %10.0f physics steps/s\n"
                "  dicestack env, 1 thread   : %8.1f episodes/s  %10.0f physics steps/s  (%.3f of bare)\n"
                "  dicestack env, %d threads  : %8.1f episodes/s  %10.0f physics steps/s  (%.2fx)\n"
                "  bare Box2D loop, %d threads: %8.1f episodes/s  (%.2fx: what this machine's cores give)",
                opt.episodes, opt.steps, config.physics.substeps, config.physics.velocity_iterations, opt.repeats,
                eps_bare, eps_bare * physics_per_episode, eps, eps * physics_per_episode, eps / eps_bare, threads,
                eps_threads, eps_threads * physics_per_episode, eps_threads / eps, threads, eps_bare_threads,
                eps_bare_threads / eps_bare);
  print_line(line);
  if (opt.sleep) {
    std::snprintf(line, sizeof line,
                  "  with body sleeping        : %8.1f episodes/s  (%.2fx); same outcome in %d of %d episodes",
                  median(sleepy), median(sleepy) / eps, same_outcome, opt.episodes);
    print_line(line);
  }
  return 0;
}

struct SnapshotOptions {
  WorldOption world;
  int episodes = 500;
  int follow = 20;
  std::uint64_t seed = 1;
  bool json = false;
};

// Largest distance between matching bodies' positions (cup and dice), m.
double position_gap(const State& a, const State& b) {
  double gap = std::hypot(a[0] - b[0], a[1] - b[1]);
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = state_index::die(i);
    gap = std::max(gap, std::hypot(a[d] - b[d], a[d + 1] - b[d + 1]));
  }
  return gap;
}

// Snapshots a random-action episode at a random step and continues from (a) the exact
// snapshot and (b) the bare 24-number state, against the uninterrupted run.
int run_snapshot(const SnapshotOptions& opt) {
  const WorldConfig config = opt.world.load();
  int exact_same = 0, bare_same = 0;
  std::vector<double> gaps;
  double exact_seconds = 0.0, bare_seconds = 0.0;
  for (int e = 0; e < opt.episodes; ++e) {
    Rng rng(derive_seed(opt.seed, static_cast<std::uint64_t>(e)));
    const int at = 10 + static_cast<int>(rng.below(140));
    std::vector<Action> actions(static_cast<std::size_t>(at + opt.follow));
    for (auto& a : actions)
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] = rng.uniform(-1.0, 1.0) * config.action.scale[k];
    World run(config, random_start_state(config, derive_seed(opt.seed + 1, static_cast<std::uint64_t>(e))));
    for (int t = 0; t < at; ++t) run.step(actions[static_cast<std::size_t>(t)]);
    const WorldSnapshot snap = run.snapshot();
    World exact(config), bare(config);
    auto t0 = std::chrono::steady_clock::now();
    exact.restore(snap);
    exact_seconds += seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    bare.set_state(snap.state());
    bare_seconds += seconds_since(t0);
    bool exact_ok = true;
    for (int t = at; t < at + opt.follow; ++t) {
      const auto& a = actions[static_cast<std::size_t>(t)];
      run.step(a);
      exact.step(a);
      bare.step(a);
      exact_ok = exact_ok && exact.state() == run.state();
    }
    exact_same += exact_ok;
    const double gap = position_gap(bare.state(), run.state());
    bare_same += gap == 0.0;
    gaps.push_back(gap);
  }
  std::sort(gaps.begin(), gaps.end());
  const double n = opt.episodes;
  const double p90 = gaps[static_cast<std::size_t>(0.9 * (gaps.size() - 1))];
  if (opt.json) {
    print_line(nlohmann::json{{"episodes", opt.episodes},
                              {"follow_steps", opt.follow},
                              {"exact_identical_fraction", exact_same / n},
                              {"bare_identical_fraction", bare_same / n},
                              {"bare_gap_median_m", median(gaps)},
                              {"bare_gap_p90_m", p90},
                              {"bare_gap_max_m", gaps.back()},
                              {"restore_us", 1e6 * exact_seconds / n},
                              {"set_state_us", 1e6 * bare_seconds / n}}
                   .dump());
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "bench snapshot: %d random-action episodes, restored at a random step, followed %d steps\n"
                "  exact snapshot  : identical in %d of %d (%.1f%%), restore %.1f us\n"
                "  bare 24 numbers : identical in %d of %d (%.1f%%), set_state %.1f us;\n"
                "                    largest body position gap after %d steps: median %.3g m, p90 %.3g m, max %.3g m",
                opt.episodes, opt.follow, exact_same, opt.episodes, 100.0 * exact_same / n, 1e6 * exact_seconds / n,
                bare_same, opt.episodes, 100.0 * bare_same / n, 1e6 * bare_seconds / n, opt.follow, median(gaps), p90,
                gaps.back());
  print_line(line);
  return 0;
}

}  // namespace

void add_bench_command(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Measure performance (run a Release build)");
  bench->require_subcommand(1);

  auto sim = std::make_shared<SimOptions>();
  CLI::App* cmd = bench->add_subcommand("sim", "Simulator throughput against a bare Box2D loop, 1 and N threads");
  sim->world.add_to(*cmd);
  cmd->add_option("--threads", sim->threads, "Threads for the parallel run (0 = all cores)")->check(threads_check())->capture_default_str();
  cmd->add_option("--episodes", sim->episodes, "Episodes per measurement")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--steps", sim->steps, "Control steps per episode")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--repeats", sim->repeats, "Measurements per figure (the median is reported)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seed", sim->seed, "Seed of the random actions")->check(seed_check())->capture_default_str();
  cmd->add_flag("--sleep", sim->sleep, "Also measure with body sleeping allowed, and compare outcomes");
  cmd->add_flag("--json", sim->json, "Print one JSON object");
  cmd->callback([sim] { run_sim(*sim); });

  auto snap = std::make_shared<SnapshotOptions>();
  cmd = bench->add_subcommand("snapshot", "Exact snapshots against restoring a bare 24-number state");
  snap->world.add_to(*cmd);
  cmd->add_option("--episodes", snap->episodes, "Episodes")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--follow", snap->follow, "Steps followed after the restore")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", snap->seed, "Seed")->check(seed_check())->capture_default_str();
  cmd->add_flag("--json", snap->json, "Print one JSON object");
  cmd->callback([snap] { run_snapshot(*snap); });

  add_bench_regressors_command(*bench);
  add_bench_load_command(*bench);
  add_bench_dataset_command(*bench);
  add_bench_optimise_command(*bench);
  add_bench_estimator_command(*bench);
  add_bench_arm_command(*bench);
  add_bench_arm_open_loop_command(*bench);
}

}  // namespace dicestack::cli
