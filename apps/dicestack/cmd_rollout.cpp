// `dicestack rollout`: one episode with a simple built-in controller; prints the outcome, a
// fingerprint of every state (for determinism checks across processes) and optionally a PNG.
#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct RolloutOptions {
  WorldOption world;
  std::uint64_t seed = 0;
  std::string start = "random";
  std::string actions = "random";
  int steps = 0;
  std::filesystem::path png;
  bool json = false;
};

int run_rollout(const RolloutOptions& opt) {
  const WorldConfig config = opt.world.load();
  DiceEnv env(config);
  State s = opt.start == "paper" ? env.reset_to(paper_start_state(config), opt.seed) : env.reset(opt.seed);
  Rng rng(derive_seed(opt.seed, 2));
  const int steps = opt.steps > 0 ? opt.steps : config.episode.max_steps;
  std::uint64_t hash = hash_state(s);
  double total_reward = 0.0;
  StepResult r;
  const auto t0 = std::chrono::steady_clock::now();
  for (int t = 0; t < steps; ++t) {
    Action a{0.0, 0.0, 0.0};
    if (opt.actions == "random")
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] = rng.uniform(-1.0, 1.0) * config.action.scale[k];
    r = env.step(a);
    hash = hash_state(r.observation, hash);
    total_reward += r.reward;
    if (r.terminated) break;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Outcome& o = env.outcome();
  if (!opt.png.empty())
    write_png(render_state(env.get_state(), config, {o.steps, o, "rollout: " + opt.actions + " actions, seed " +
                                                                     std::to_string(opt.seed)}),
              opt.png);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  if (opt.json) {
    nlohmann::json j{{"seed", opt.seed},         {"steps", o.steps},
                     {"state_hash", hex},        {"dice_in_cup", o.dice_in_cup},
                     {"stacked", o.stacked},     {"wall_contact", o.wall_contact},
                     {"realistic_success", o.realistic_success()}, {"return", total_reward},
                     {"seconds", seconds}};
    print_line(j.dump());
  } else {
    char line[256];
    std::snprintf(line, sizeof line,
                  "%d steps (%.2f s simulated, %.1f ms wall): dice in cup %d, stacked %s, wall contact %s, "
                  "realistic success %s\nstate hash %s",
                  o.steps, o.steps * config.physics.control_dt, 1e3 * seconds, o.dice_in_cup, o.stacked ? "yes" : "no",
                  o.wall_contact ? "yes" : "no", o.realistic_success() ? "yes" : "no", hex);
    print_line(line);
    if (!opt.png.empty()) print_line("wrote " + opt.png.string());
  }
  return 0;
}

}  // namespace

void add_rollout_command(CLI::App& app) {
  auto opt = std::make_shared<RolloutOptions>();
  CLI::App* cmd = app.add_subcommand("rollout", "Run one episode with random or zero actions and report its outcome");
  opt->world.add_to(*cmd);
  cmd->add_option("--seed", opt->seed, "Seed of the start state and the actions")->check(seed_check())->capture_default_str();
  cmd->add_option("--start", opt->start, "Start state: random (from the seed) or paper")
      ->check(CLI::IsMember({"random", "paper"}))
      ->capture_default_str();
  cmd->add_option("--actions", opt->actions, "Actions: random (uniform in the optimisers' scale) or still (zero)")
      ->check(CLI::IsMember({"random", "still"}))
      ->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Control steps (default: the world's episode.max_steps)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--png", opt->png, "Render the last frame to this PNG");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_rollout(*opt); });
}

}  // namespace dicestack::cli
