// The paper's baselines without demonstrations: `dicestack optimise` (open-loop sequences,
// Section V-B), `dicestack reinforce` (Section V-C), and `dicestack bench optimise`:
// evaluations per second of each optimiser against the bare simulator.
#include <algorithm>
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/open_loop.hpp>
#include <dicestack/core/reinforce.hpp>
#include <dicestack/core/rrt.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/demo_set.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct OptimiseCommandOptions {
  WorldOption world;
  OptimiseOptions optimiser;
  OpenLoopSettings settings;
  double gravity_scale = 1.0, noise = 0.0, discount = -1.0;
  int threads = 0;
  std::filesystem::path out;
  bool json = false;
};

// The world the options describe: gravity scaled, action noise and discount set.
WorldConfig open_loop_world(const OptimiseCommandOptions& opt) {
  WorldConfig w = opt.world.load();
  w.physics.gravity.x *= opt.gravity_scale;
  w.physics.gravity.y *= opt.gravity_scale;
  w.physics.action_noise = opt.noise;
  if (opt.discount >= 0.0) w.cost.gamma = opt.discount;
  return w;
}

// A baseline's action sequence played once from the paper's start, as an episode.
Episode replay(const WorldConfig& world, const std::vector<Action>& actions, std::uint64_t seed, const std::string& origin) {
  DiceEnv env(world);
  Episode e;
  e.name = "episode_0000";
  e.origin = origin;
  e.seed = seed;
  State s = env.reset_to(paper_start_state(world), e.seed);
  for (const Action& a : actions) {
    e.states.push_back(s);
    e.actions.push_back(a);
    e.sources.push_back(StepSource::policy);
    const StepResult r = env.step(a);
    s = r.observation;
    e.rewards.push_back(r.reward);
    e.terminated = r.terminated;
  }
  if (!e.states.empty()) {
    e.final_state = s;
    e.truncated = !e.terminated;
  }
  e.outcome = env.outcome();
  return e;
}

void write_episode_set(const WorldConfig& world, const Episode& e, const std::string& description,
                       const std::string& provenance, const std::filesystem::path& out) {
  DemoSet set;
  set.world = world;
  set.description = description;
  set.provenance = provenance;
  set.episodes.push_back(e);
  write_demo_set(set, out);
}

// A baseline's episode outcome, for its JSON summary and its text line.
nlohmann::json outcome_json(const Outcome& o) {
  return {{"dice_in_cup", o.dice_in_cup}, {"stacked", o.stacked}, {"wall_contact", o.wall_contact},
          {"realistic_success", o.realistic_success()}};
}

std::string outcome_text(const Outcome& o) {
  auto yes = [](bool b) { return b ? "yes" : "no"; };
  return "dice in cup " + std::to_string(o.dice_in_cup) + ", stacked " + yes(o.stacked) + ", wall contact " +
         yes(o.wall_contact) + ", realistic success " + yes(o.realistic_success());
}

// Writes `summary` (with `curve` under `curve_key`) to `file` atomically, then prints the summary
// as JSON or the text.
int finish_baseline(const std::filesystem::path& file, nlohmann::json summary, const std::string& curve_key,
                    const nlohmann::json& curve, bool json, const std::string& text) {
  nlohmann::json saved = summary;
  saved["format"] = kBaselineFormat;
  saved["version"] = 1;
  if (!curve.is_null()) saved[curve_key] = curve;
  AtomicFile f(file, Ownership::json_object("dicestack baseline summary", kBaselineFormat));
  f.stream() << saved.dump(1);
  f.commit();
  print_line(json ? summary.dump() : text);
  return 0;
}

int run_optimise(OptimiseCommandOptions opt) {
  check_demo_set_replaceable(opt.out);  // refuse a user's folder before any work
  const WorldConfig world = open_loop_world(opt);
  OpenLoopProblem problem(world, opt.settings, opt.threads);
  ProgressBar bar;
  const OptimiseResult r = optimise(problem, opt.optimiser, [&](int evaluations, double best) {
    char text[160];
    std::snprintf(text, sizeof text, "%s: %d/%d evaluations, best cost %.4g", opt.optimiser.method.c_str(), evaluations,
                  opt.optimiser.evaluations, best);
    bar.update(static_cast<double>(evaluations) / opt.optimiser.evaluations, text);
  });
  bar.finish();
  // With noise, the first repeat's noise seed.
  const Episode best = replay(problem.world(), problem.actions(r.best.data()), derive_seed(opt.settings.seed, 0), "dicestack optimise");
  write_episode_set(problem.world(), best, "best open-loop sequence of dicestack optimise --method " + opt.optimiser.method,
                    "dicestack optimise --method " + opt.optimiser.method + " --steps " + std::to_string(opt.settings.steps) +
                        " --evaluations " + std::to_string(opt.optimiser.evaluations) + " --seed " + std::to_string(opt.optimiser.seed),
                    opt.out);
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
  return finish_baseline(opt.out / "optimise.json", j, "curve", curve, opt.json,
                         line + ("best sequence: " + outcome_text(best.outcome) + " -> " + opt.out.string()));
}

void add_problem_options(CLI::App& cmd, OptimiseCommandOptions& opt) {
  opt.world.add_to(cmd);
  cmd.add_option("--steps", opt.settings.steps, "Control steps of the sequence (the original used 50, the paper's text 30)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd.add_option("--gravity-scale", opt.gravity_scale, "Multiplies gravity (the paper's text: 3)")->capture_default_str();
  cmd.add_option("--noise", opt.noise, "Std of action noise, as a fraction of the action scale (0: deterministic)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd.add_option("--repeats", opt.settings.repeats, "Noisy runs averaged per evaluation")->check(CLI::PositiveNumber)->capture_default_str();
  cmd.add_option("--discount", opt.discount, "Discount gamma of eq. 6 (default: the world's, 0.1)")->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--threads", opt.threads, "Threads (0 = all cores); results do not depend on it")->capture_default_str();
}

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

struct ReinforceCommandOptions {
  WorldOption world;
  ReinforceOptions reinforce;
  std::filesystem::path out;
  bool json = false;
};

int run_reinforce(const ReinforceCommandOptions& opt) {
  check_demo_set_replaceable(opt.out);
  const WorldConfig world = opt.world.load();
  ProgressBar bar;
  const ReinforceResult r = reinforce(world, opt.reinforce, [&](const ReinforcePoint& p) {
    char text[160];
    std::snprintf(text, sizeof text, "reinforce: iteration %d/%d, mean return %.3g, greedy cost %.4g", p.iteration,
                  opt.reinforce.iterations, p.mean_return, p.greedy_cost);
    bar.update(static_cast<double>(p.iteration) / opt.reinforce.iterations, text);
  });
  bar.finish();
  WorldConfig played = world;
  played.episode.max_steps = std::max(played.episode.max_steps, opt.reinforce.steps);
  const Episode greedy = replay(played, r.greedy_actions, 0, "dicestack reinforce");
  write_episode_set(played, greedy, "the mean actions of the policy learned by dicestack reinforce",
                    "dicestack reinforce --iterations " + std::to_string(opt.reinforce.iterations) + " --batch " +
                        std::to_string(opt.reinforce.batch) + " --steps " + std::to_string(opt.reinforce.steps) + " --seed " +
                        std::to_string(opt.reinforce.seed),
                    opt.out);
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
  return finish_baseline(opt.out / "reinforce.json", j, "curve (iteration, mean return, greedy cost)", curve, opt.json,
                         line + ("greedy policy: " + outcome_text(greedy.outcome) + " -> " + opt.out.string()));
}

struct RrtCommandOptions {
  WorldOption world;
  RrtOptions rrt;
  std::filesystem::path out;
  bool json = false;
};

int run_rrt(const RrtCommandOptions& opt) {
  check_demo_set_replaceable(opt.out);
  const WorldConfig world = opt.world.load();
  ProgressBar bar;
  const RrtResult r = rrt(world, opt.rrt, [&](int nodes, double best) {
    char text[160];
    std::snprintf(text, sizeof text, "rrt: %d/%d nodes, nearest to the goal %.4g", nodes, opt.rrt.nodes, best);
    bar.update(static_cast<double>(nodes) / std::max(1, opt.rrt.nodes), text);
  });
  bar.finish();
  WorldConfig played = world;
  played.episode.max_steps = std::max(played.episode.max_steps, static_cast<int>(r.actions.size()));
  // When no node got nearer the goal than the start, there is no path: only rrt.json is written.
  const Episode path = r.actions.empty() ? Episode{} : replay(played, r.actions, 0, "dicestack rrt");
  if (r.actions.empty()) std::filesystem::create_directories(opt.out);
  else
    write_episode_set(played, path, "the path to the node nearest the goal in the tree of dicestack rrt",
                      "dicestack rrt --nodes " + std::to_string(opt.rrt.nodes) + " --extend-steps " +
                          std::to_string(opt.rrt.extend_steps) + " --seed " + std::to_string(opt.rrt.seed),
                      opt.out);
  const double rate = static_cast<double>(r.simulated_steps) / std::max(r.seconds, 1e-9);
  nlohmann::json j{{"nodes", r.nodes},          {"simulated_steps", r.simulated_steps}, {"seconds", r.seconds},
                   {"steps_per_second", rate},  {"best_distance", r.best_distance},   {"path_steps", r.actions.size()},
                   {"seed", opt.rrt.seed},      {"out", opt.out.string()}};
  j.update(outcome_json(path.outcome));
  char line[256];
  std::snprintf(line, sizeof line, "rrt: %d nodes, %lld simulated steps in %.1f s (%.0f steps/s); nearest to the goal %.4g after %zu steps\n",
                r.nodes, r.simulated_steps, r.seconds, rate, r.best_distance, r.actions.size());
  return finish_baseline(opt.out / "rrt.json", j, "", nullptr, opt.json,
                         line + ("path (none if no node got nearer than the start): " + outcome_text(path.outcome) + " -> " +
                                 opt.out.string()));
}

}  // namespace

void add_rrt_command(CLI::App& app) {
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
  cmd->add_option("--threads", r.threads, "Threads (0 = all cores); results do not depend on it")->capture_default_str();
  cmd->add_option("--out", opt->out, "Folder for the best path (a demonstration set) and rrt.json")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_rrt(*opt); });
}

void add_reinforce_command(CLI::App& app) {
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
  cmd->add_option("--threads", r.threads, "Threads (0 = all cores); results do not depend on it")->capture_default_str();
  cmd->add_option("--out", opt->out, "Folder for the greedy episode (a demonstration set) and reinforce.json")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_reinforce(*opt); });
}

void add_optimise_command(CLI::App& app) {
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
  cmd->callback([opt] {
    opt->settings.seed = opt->optimiser.seed;
    run_optimise(*opt);
  });
}

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
