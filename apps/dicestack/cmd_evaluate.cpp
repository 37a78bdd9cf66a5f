// `dicestack evaluate`: roll a trained policy out from N random starts and report what it
// achieved, with 95% Wilson intervals; with --demos, also its eq. 9 errors.
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/metrics.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct EvaluateOptions {
  WorldOption world;
  std::filesystem::path model, demos, save_rollouts;
  int episodes = 20;
  std::uint64_t seed = 0;
  int threads = 0;
  std::string push = "none";
  bool json = false;
};

nlohmann::json rate_json(const Rate& r) { return {r.value, r.low, r.high}; }

int run_evaluate(const EvaluateOptions& opt) {
  const WorldConfig world = opt.world.load();
  auto model = std::make_shared<const Model>(load_model(opt.model));
  if (!opt.save_rollouts.empty()) check_demo_set_replaceable(opt.save_rollouts);  // before any work
  std::vector<Episode> rollouts;
  const EvalStats s = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, world, opt.episodes, opt.seed,
                               opt.threads, initial_push_from(opt.push), opt.save_rollouts.empty() ? nullptr : &rollouts);
  if (!opt.save_rollouts.empty()) {
    DemoSet set;
    set.world = world;
    set.description = "rollouts of " + opt.model.string();
    set.provenance = "dicestack evaluate --model " + opt.model.string() + " --episodes " + std::to_string(opt.episodes) +
                     " --seed " + std::to_string(opt.seed) + "; episode i starts from evaluation_start_seed(seed, i)";
    set.episodes = std::move(rollouts);
    write_demo_set(set, opt.save_rollouts);
  }
  nlohmann::json j{{"model", opt.model.string()},
                   {"regressor", model->regressor().name()},
                   {"features", model->features().name()},
                   {"episodes", s.episodes},
                   {"seed", opt.seed},
                   {"initial_push", opt.push},
                   {"dice_in_cup_mean", s.dice_in_cup_mean},
                   {"dice_in_cup_3_rate", s.dice_in_cup_3.value},
                   {"stacked_rate", s.stacked.value},
                   {"wall_contact_rate", s.wall_contact.value},
                   {"realistic_success_rate", s.realistic_success.value},
                   {"stacked_rate_ci95", rate_json(s.stacked)},
                   {"wall_contact_rate_ci95", rate_json(s.wall_contact)},
                   {"realistic_success_rate_ci95", rate_json(s.realistic_success)},
                   {"mean_episode_length", s.mean_length},
                   {"us_per_step", s.policy_us_per_step},
                   {"seconds", s.seconds}};
  if (!opt.demos.empty()) {
    const DemoSet set = read_demo_set(opt.demos);
    const Split split = split_by_episode(set.episodes, model->features());
    const auto sigma = column_sigma(split.train.y);
    j["train_error"] = scaled_l1_error(split.train.y, model->predict(split.train.x), sigma);
    if (split.test.rows() > 0) j["test_error"] = scaled_l1_error(split.test.y, model->predict(split.test.x), sigma);
    j["split"] = split.description;
  }
  if (opt.json) {
    print_line(j.dump());
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "%s (%s): %d episodes from seed %llu\n"
                "  realistic success %.1f%% [%.1f, %.1f], stacked %.1f%% [%.1f, %.1f], wall contact %.1f%% [%.1f, %.1f]\n"
                "  dice in cup (most, mean) %.2f, all three %.1f%%, mean length %.0f steps, %.2f us per step",
                opt.model.string().c_str(), model->regressor().name().c_str(), s.episodes,
                static_cast<unsigned long long>(opt.seed), 100 * s.realistic_success.value, 100 * s.realistic_success.low,
                100 * s.realistic_success.high, 100 * s.stacked.value, 100 * s.stacked.low, 100 * s.stacked.high,
                100 * s.wall_contact.value, 100 * s.wall_contact.low, 100 * s.wall_contact.high, s.dice_in_cup_mean,
                100 * s.dice_in_cup_3.value, s.mean_length, s.policy_us_per_step);
  print_line(line);
  if (j.contains("train_error"))
    print_line("  train error " + std::to_string(j["train_error"].get<double>()) +
               (j.contains("test_error") ? ", test error " + std::to_string(j["test_error"].get<double>()) : "") + " (" +
               j["split"].get<std::string>() + ")");
  return 0;
}

}  // namespace

void add_evaluate_command(CLI::App& app) {
  auto opt = std::make_shared<EvaluateOptions>();
  CLI::App* cmd = app.add_subcommand("evaluate", "Roll a trained policy out and report its outcomes");
  opt->world.add_to(*cmd);
  cmd->add_option("--model", opt->model, "Model file written by `dicestack train`")->required()->check(CLI::ExistingFile);
  cmd->add_option("--demos", opt->demos, "Also report train and test error (eq. 9) on this set")->check(CLI::ExistingDirectory);
  cmd->add_option("--episodes", opt->episodes, "Rollouts from random starts")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the starts")->check(seed_check())->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->capture_default_str();
  cmd->add_option("--initial-push", opt->push, "The paper's jump-start: none, left or right")
      ->check(CLI::IsMember({"none", "left", "right"}))
      ->capture_default_str();
  cmd->add_option("--save-rollouts", opt->save_rollouts,
                  "Also write the rollouts as a demonstration set (source policy; outcomes in meta.json)");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_evaluate(*opt); });
}

}  // namespace dicestack::cli
