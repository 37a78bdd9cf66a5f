// `dicestack rollout`: one episode with a simple built-in controller; prints the outcome, a
// fingerprint of every state (for determinism checks across processes) and optionally a PNG.
#include <chrono>
#include <cstdio>
#include <span>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/learners/evaluate.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct RolloutOptions {
  WorldOption world;
  std::uint64_t seed = 0;
  std::string start = "random";
  std::string actions = "random";
  std::string controller = "cup";
  int steps = 0;
  std::filesystem::path png;
  bool json = false;
};

// Uniform random actions of `kind` in their scale (action_scale: the optimisers' range for the
// cup, the torque limits for joint torques), from their own stream, or zeros.
class BuiltinController final : public Policy {
 public:
  BuiltinController(bool random, ActionKind kind, std::span<const double> scale, std::uint64_t seed)
      : random_(random), kind_(kind), scale_(scale.begin(), scale.end()), rng_(seed) {}
  Action act(const History&) override {
    Action a = Action::zeros(kind_);
    if (random_)
      for (std::size_t k = 0; k < a.size(); ++k) a[k] = rng_.uniform(-1.0, 1.0) * scale_[k];
    return a;
  }
  std::string name() const override { return random_ ? "random actions" : "still"; }

 private:
  bool random_;
  ActionKind kind_;
  std::vector<double> scale_;
  Rng rng_;
};

int run_rollout(const RolloutOptions& opt) {
  const WorldConfig config = opt.world.load();
  const ActionKind kind = controller_kind(opt.controller);
  if (kind == ActionKind::joint_torque && config.embodiment != Embodiment::arm)
    throw ConfigError("rollout: --controller joint_torque drives an arm's joints: give --embodiment arm");
  DiceEnv env(config);
  // As DiceEnv::reset(seed) starts: the random start of the seed, the noise from its stream 1.
  const State start = opt.start == "paper" ? paper_start_state(config) : random_start_state(config, opt.seed);
  const std::uint64_t noise_seed = opt.start == "paper" ? opt.seed : derive_seed(opt.seed, 1);
  BuiltinController controller(opt.actions == "random", kind, action_scale(config, kind), derive_seed(opt.seed, 2));
  dicestack::RolloutOptions options;
  options.max_steps = static_cast<std::size_t>(opt.steps > 0 ? opt.steps : config.episode.max_steps);
  const auto t0 = std::chrono::steady_clock::now();
  const Episode e = rollout(env, controller, start, noise_seed, StepSource::policy, options);
  std::uint64_t hash = hash_state(e.states.front());
  for (std::size_t t = 1; t < e.states.size(); ++t) hash = hash_state(e.states[t], hash);
  hash = hash_state(*e.final_state, hash);
  double total_reward = 0.0;
  for (double r : e.rewards) total_reward += r;
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
  cmd->add_option("--actions", opt->actions, "Actions: random (uniform in the optimisers' scale, or within the torque limits) or still (zero)")
      ->check(CLI::IsMember({"random", "still"}))
      ->capture_default_str();
  add_controller_option(*cmd, opt->controller,
                        "What the actions drive: cup (its velocity changes; on the arm through the cup controller) or "
                        "joint_torque (the arm's four torques, with --embodiment arm; still: none, and the arm falls)");
  cmd->add_option("--steps", opt->steps, "Control steps (default and most: the world's episode.max_steps, where the episode is truncated)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--png", opt->png, "Render the last frame to this PNG");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_rollout(*opt); });
}

}  // namespace dicestack::cli
