// `dicestack bench estimator`: what the state estimator costs per step beside the simulator,
// and how far its estimate is from the state, per state number, at each sensing level.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/estimator.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/perturbed_env.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/record.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct EstimatorBenchOptions {
  WorldOption world;
  std::string expert = "scripted";
  std::string estimator = "kalman";
  int episodes = 20;
  std::uint64_t seed = 1000;
  bool json = false;
};

// One sensing factor at one level over the episodes: the raw observation's and the estimate's
// mean |error| per state number (in its spread), and the time per step of each part.
struct Cell {
  std::string factor, level;
  State raw{}, estimated{};
  double estimator_us = 0.0, world_us = 0.0;
  long long steps = 0;
};

using Clock = std::chrono::steady_clock;

double micros(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::micro>(b - a).count(); }

// The expert acts on the estimate (its feedback; its plan reads the world) while the episode
// shows it the raw observation, so both errors are measured on the same episodes.
Cell measure(const WorldConfig& world, const EstimatorBenchOptions& opt, const std::string& factor, const std::string& level) {
  Cell c{factor, level};
  DiceEnv pooled(world);
  const EstimatorConfig config = estimator_config(opt.estimator);
  for (int i = 0; i < opt.episodes; ++i) {
    const std::uint64_t seed = evaluation_start_seed(opt.seed, static_cast<std::uint64_t>(i));
    PerturbedEnv env(pooled, perturbation_factor(factor, level), seed);
    auto estimator = make_estimator(config, world, env.draw());
    auto expert = make_expert(opt.expert);
    expert->reset(seed);
    State shown = env.reset(seed);
    if (estimator) shown = estimator->start(shown);
    for (int t = 0; t < world.episode.max_steps; ++t) {
      const Action chosen = env.clip(expert->act(env.env(), {}, &shown));
      const auto t0 = Clock::now();
      const PerturbedStep s = env.step(chosen);
      const auto t1 = Clock::now();
      shown = estimator ? estimator->update(chosen, s.shown) : s.shown;
      const auto t2 = Clock::now();
      c.world_us += micros(t0, t1);
      c.estimator_us += micros(t1, t2);
      ++c.steps;
      for (std::size_t k = 0; k < kStateDim; ++k) {
        const double spread = observation_spread()[k], truth = s.result.observation[k];
        c.raw[k] += std::abs(s.shown[k] - truth) / spread;
        c.estimated[k] += std::abs(shown[k] - truth) / spread;
      }
      if (s.result.terminated || s.result.truncated) break;
    }
  }
  for (std::size_t k = 0; k < kStateDim; ++k) {
    c.raw[k] /= static_cast<double>(c.steps);
    c.estimated[k] /= static_cast<double>(c.steps);
  }
  c.world_us /= static_cast<double>(c.steps);
  c.estimator_us /= static_cast<double>(c.steps);
  return c;
}

// The simulator's error over one control step from a true state, RMS per state number in its
// spread, along the built-in set's episodes: the table the estimator's process noise is made
// of (kModelError in estimator.cpp).
State model_error(const WorldConfig& world) {
  const DemoSet set = read_demo_set(builtin_demo_set(world));
  World model(world);
  State squares{};
  double steps = 0.0;
  for (const Episode& e : set.episodes)
    for (std::size_t t = 0; t + 1 < e.states.size(); ++t) {
      model.set_state(e.states[t]);
      model.step(e.actions[t]);
      const State predicted = model.state();
      for (std::size_t k = 0; k < kStateDim; ++k) {
        const double d = (predicted[k] - e.states[t + 1][k]) / observation_spread()[k];
        squares[k] += d * d;
      }
      steps += 1.0;
    }
  for (double& v : squares) v = std::sqrt(v / steps);
  return squares;
}

double mean(const State& s) {
  double sum = 0.0;
  for (double v : s) sum += v;
  return sum / kStateDim;
}

void print_cells(const std::vector<Cell>& cells, const State& model, const EstimatorBenchOptions& opt) {
  std::printf("dicestack bench estimator: %s, expert %s acting on the estimate, %d episodes per row from seed %llu\n\n",
              opt.estimator.c_str(), opt.expert.c_str(), opt.episodes, static_cast<unsigned long long>(opt.seed));
  std::printf("| factor | level | error raw | error estimated | estimator us/step | world us/step |\n|---|---|---:|---:|---:|---:|\n");
  for (const Cell& c : cells)
    std::printf("| %s | %s | %.4f | %.4f | %.1f | %.1f |\n", c.factor.c_str(), c.level.c_str(), mean(c.raw),
                mean(c.estimated), c.estimator_us, c.world_us);
  std::printf("\nMean |error| per state number, in its spread, raw / estimated:\n\n| number |");
  for (const Cell& c : cells) std::printf(" %s %s |", c.factor.c_str(), c.level.c_str());
  std::printf("\n|---|");
  for (std::size_t i = 0; i < cells.size(); ++i) std::printf("---:|");
  std::printf("\n");
  for (std::size_t k = 0; k < kStateDim; ++k) {
    std::printf("| %s |", std::string(state_names()[k]).c_str());
    for (const Cell& c : cells) std::printf(" %.3f / %.3f |", c.raw[k], c.estimated[k]);
    std::printf("\n");
  }
  std::printf("\nThe simulator's one-step error from true states along the built-in set (RMS, in spreads; the "
              "estimator's process noise is a multiple of it):\n\n| number | error |\n|---|---:|\n");
  for (std::size_t k = 0; k < kStateDim; ++k) std::printf("| %s | %.4f |\n", std::string(state_names()[k]).c_str(), model[k]);
}

int run_estimator_bench(const EstimatorBenchOptions& opt) {
  const WorldConfig world = opt.world.load();
  std::vector<Cell> cells;
  for (const char* factor : {"observation_noise", "observation_delay"})
    for (const char* level : {"easy", "medium", "hard"}) cells.push_back(measure(world, opt, factor, level));
  const State model = model_error(world);
  if (!opt.json) {
    print_cells(cells, model, opt);
    return 0;
  }
  nlohmann::json out = nlohmann::json::array();
  for (const Cell& c : cells)
    out.push_back({{"factor", c.factor}, {"level", c.level}, {"error_raw", c.raw}, {"error_estimated", c.estimated},
                   {"estimator_us_per_step", c.estimator_us}, {"world_us_per_step", c.world_us}});
  print_line(nlohmann::json{{"rows", out}, {"model_error", model}}.dump());
  return 0;
}

}  // namespace

void add_bench_estimator_command(CLI::App& bench) {
  auto opt = std::make_shared<EstimatorBenchOptions>();
  CLI::App* cmd = bench.add_subcommand("estimator",
                                       "The state estimator's cost per step beside the simulator's, and its error per "
                                       "state number at each sensing level");
  opt->world.add_to(*cmd);
  cmd->add_option("--expert", opt->expert, "The expert whose feedback acts on the estimate: scripted, mpc (tracker needs recordings)")
      ->check(CLI::IsMember({"scripted", "mpc"}))
      ->capture_default_str();
  add_estimator_option(*cmd, opt->estimator)
      ->description("The estimator measured: none (the observations), kalman or particle[:N] (docs/robustness.md)")
      ->capture_default_str();
  cmd->add_option("--episodes", opt->episodes, "Episodes per row")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the first episode (then seed + 1, ...)")->check(seed_check())->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON array");
  cmd->callback([opt] { run_estimator_bench(*opt); });
}

}  // namespace dicestack::cli
