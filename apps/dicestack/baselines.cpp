#include "baselines.hpp"

#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

namespace dicestack::cli {

WorldConfig open_loop_world(const OptimiseCommandOptions& opt) {
  WorldConfig w = opt.world.load();
  w.physics.gravity.x *= opt.gravity_scale;
  w.physics.gravity.y *= opt.gravity_scale;
  w.physics.action_noise = opt.noise;
  if (opt.discount >= 0.0) w.cost.gamma = opt.discount;
  return w;
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
  cmd.add_option("--threads", opt.threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
}

Episode replay(const WorldConfig& world, const std::vector<Action>& actions, std::uint64_t seed, const std::string& origin) {
  Episode e;
  if (!actions.empty()) {  // the one rollout loop, playing the actions from the paper's start
    DiceEnv env(world);
    Episode played;
    played.actions = actions;
    PlaybackPolicy playback(played);
    RolloutOptions options;
    options.max_steps = actions.size();
    e = rollout(env, playback, paper_start_state(world), seed, StepSource::policy, options);
  }
  e.name = "episode_0000";
  e.origin = origin;
  e.seed = seed;
  return e;
}

nlohmann::json outcome_json(const Outcome& o) {
  return {{"dice_in_cup", o.dice_in_cup}, {"stacked", o.stacked}, {"wall_contact", o.wall_contact},
          {"realistic_success", o.realistic_success()}};
}

std::string outcome_text(const Outcome& o) {
  auto yes = [](bool b) { return b ? "yes" : "no"; };
  return "dice in cup " + std::to_string(o.dice_in_cup) + ", stacked " + yes(o.stacked) + ", wall contact " +
         yes(o.wall_contact) + ", realistic success " + yes(o.realistic_success());
}

int finish_baseline(const BaselineOutput& o, bool json, const std::string& text) {
  nlohmann::json saved = o.summary;
  saved["format"] = kBaselineFormat;
  saved["version"] = 1;
  if (!o.curve.is_null()) saved[o.curve_key] = o.curve;
  DemoSet set;
  set.world = o.world;
  set.description = o.description;
  set.provenance = o.provenance;
  if (o.episode) set.episodes.push_back(*o.episode);
  write_demo_set(set, o.out, {{o.summary_file, saved.dump(1)}});
  print_line(json ? o.summary.dump() : text);
  return 0;
}

}  // namespace dicestack::cli
