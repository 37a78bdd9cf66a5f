// `dicestack evaluate`: roll a trained policy out from N random starts and report what it
// achieved, with 95% Wilson intervals; with --demos, also its eq. 9 errors.
#include <cstdio>
#include <optional>

#include <dicestack/core/error.hpp>
#include <dicestack/core/video.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/report.hpp>
#include <dicestack/experiments/results_page.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct EvaluateOptions {
  WorldOption world;
  std::filesystem::path model, demos, save_rollouts, video_dir, report;
  std::string video_format = "mp4";
  int episodes = 20;
  std::uint64_t seed = 0;
  int threads = 0;
  std::string push = "none";
  std::string perturb = "none";
  std::string estimator;  // empty: the model's own
  bool json = false;
};

// Recordings hold the cup's actions: a policy in joint torques cannot be scored on them (its
// rollouts are saved as an arm's episodes in joint torques).
void check_torque_outputs(const EvaluateOptions& opt, const Model& model) {
  if (model.features().action_kind() != ActionKind::joint_torque) return;
  if (!opt.demos.empty())
    throw ConfigError("evaluate: --demos scores a policy on recordings of the cup's actions; " + opt.model.string() +
                      " answers joint torques");
}

int run_evaluate(const EvaluateOptions& opt, Cluster& cluster) {
  const WorldConfig world = opt.world.load();
  const Perturbation perturbation = load_perturbation(opt.perturb, world);  // before any work
  auto model = std::make_shared<const Model>(load_model(opt.model));
  check_map_world(model->features(), world);
  check_torque_outputs(opt, *model);
  const std::string estimator = estimator_for(opt.estimator, *model);
  if (!opt.save_rollouts.empty()) check_demo_set_replaceable(opt.save_rollouts);  // before any work
  // A saved episode keeps the true states and replays what the sensors gave (dataset.cpp); the
  // estimates a policy saw are not replayed, so a set saved behind an estimator would mislead.
  if (!opt.save_rollouts.empty() && estimator != "none" && senses(perturbation))
    throw ConfigError("evaluate: --save-rollouts with --estimator: a saved set replays what the sensors gave, not the "
                      "estimates the policy saw; save the rollouts without the estimator");
  if (!opt.report.empty()) check_report_replaceable(opt.report);
  if (!opt.video_dir.empty() && std::filesystem::exists(opt.video_dir) && !std::filesystem::is_directory(opt.video_dir))
    throw InputError(opt.video_dir.string() + ": --video-dir exists and is not a folder");
  std::optional<Score> errors;  // before the rollouts, so that a bad set fails at once; the root prints them
  if (!opt.demos.empty() && cluster.is_root())
    errors = score(*model, DemoSplit(read_demo_set(resolve_demo_set(opt.demos, world)).episodes, "episodes"));
  const bool keep = !opt.save_rollouts.empty() || !opt.video_dir.empty() || !opt.report.empty();
  std::vector<Episode> rollouts;
  std::vector<EpisodeResult> results;
  EvalRequest request;
  request.episodes = opt.episodes;
  request.seed = opt.seed;
  request.threads = opt.threads;
  request.push = initial_push_from(opt.push);
  request.perturbation = perturbation;
  request.estimator = estimator_config(estimator);
  request.actions = model->features().action_kind();
  request.rollouts = keep ? &rollouts : nullptr;
  request.results = &results;
  const EvalStats s = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, world, request, cluster);
  if (!cluster.is_root()) return 0;  // the root writes and prints
  const EvaluationRun run{opt.model.string(), opt.seed, opt.push, opt.perturb, opt.world.start, estimator};
  if (!opt.report.empty())
    write_report_folder(evaluation_board(run, *model, s, results, rollouts, world, errors ? &*errors : nullptr), opt.report);
  if (!opt.video_dir.empty()) {
    // One video per rollout, named as --save-rollouts names its episodes (as robomimic's
    // run_trained_agent writes one per rollout).
    std::filesystem::create_directories(opt.video_dir);
    for (std::size_t i = 0; i < rollouts.size(); ++i) {
      std::vector<State> states = rollouts[i].states;
      if (rollouts[i].final_state) states.push_back(*rollouts[i].final_state);
      char name[48];
      std::snprintf(name, sizeof name, "episode_%04zu.%s", i, opt.video_format.c_str());
      write_frames(states, world,
                   model->regressor().name() + " rollout " + std::to_string(i) + ", seed " + std::to_string(opt.seed),
                   opt.video_dir / name);
    }
  }
  if (!opt.save_rollouts.empty()) {
    DemoSet set;
    set.world = world;
    set.description = "rollouts of " + opt.model.string();
    set.provenance = "dicestack evaluate --model " + opt.model.string() + " --episodes " + std::to_string(opt.episodes) +
                     (opt.perturb == "none" ? "" : " --perturb " + opt.perturb) +
                     (estimator == "none" ? "" : " --estimator " + estimator) +
                     (opt.world.start == "random" ? "" : " --start " + opt.world.start) + " --seed " + std::to_string(opt.seed) + "; episode i starts from evaluation_start_seed(seed, i)";
    set.episodes = std::move(rollouts);
    write_demo_set(set, opt.save_rollouts);
  }
  if (opt.json) {
    print_line(evaluation_json(run, *model, s, errors ? &*errors : nullptr));
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "%s (%s): %d episodes%s from seed %llu%s\n"
                "  realistic success %.1f%% [%.1f, %.1f], stacked %.1f%% [%.1f, %.1f], wall contact %.1f%% [%.1f, %.1f]\n"
                "  dice in cup (most, mean) %.2f, all three %.1f%%, mean length %.0f steps, %.2f us per step",
                opt.model.string().c_str(), model->regressor().name().c_str(), s.episodes,
                opt.world.start == "random" ? "" : (" from " + opt.world.start + " starts").c_str(),
                static_cast<unsigned long long>(opt.seed),
                opt.perturb == "none" ? "" : (", perturbed: " + opt.perturb + (estimator == "none" ? "" : ", estimator " + estimator)).c_str(),
                100 * s.realistic_success.value, 100 * s.realistic_success.low,
                100 * s.realistic_success.high, 100 * s.stacked.value, 100 * s.stacked.low, 100 * s.stacked.high,
                100 * s.wall_contact.value, 100 * s.wall_contact.low, 100 * s.wall_contact.high, s.dice_in_cup_mean,
                100 * s.dice_in_cup_3.value, s.mean_length, s.policy_us_per_step);
  print_line(line);
  if (errors)
    print_line("  train error " + std::to_string(errors->train_error) +
               (errors->test_error ? ", test error " + std::to_string(*errors->test_error) : "") + " (" + errors->split +
               ")");
  return 0;
}

}  // namespace

void add_evaluate_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<EvaluateOptions>();
  CLI::App* cmd = app.add_subcommand("evaluate", "Roll a trained policy out and report its outcomes");
  opt->world.add_to(*cmd, true);
  cmd->add_option("--model", opt->model, "Model file written by `dicestack train`")->required()->check(CLI::ExistingFile);
  cmd->add_option("--demos", opt->demos,
                  "Also report train and test error (eq. 9) on this set: a folder, `builtin` or `human`");
  cmd->add_option("--episodes", opt->episodes, "Rollouts from random starts")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the starts")->check(seed_check())->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--initial-push", opt->push, "The paper's jump-start: none, left or right")
      ->check(CLI::IsMember({"none", "left", "right"}))
      ->capture_default_str();
  cmd->add_option("--perturb", opt->perturb,
                  "Perturbed worlds: none, easy, medium, hard (every factor at that level) or a perturbation file "
                  "(docs/robustness.md)")
      ->capture_default_str();
  add_estimator_option(*cmd, opt->estimator);
  cmd->add_option("--save-rollouts", opt->save_rollouts,
                  "Also write the rollouts as a demonstration set (source policy; outcomes in meta.json)");
  cmd->add_option("--video-dir", opt->video_dir,
                  "Also draw one video per rollout into this folder (episode_<i>.mp4, i as in --save-rollouts)");
  cmd->add_option("--video-format", opt->video_format, "mp4, avi or gif")
      ->check(CLI::IsMember({"mp4", "avi", "gif"}))
      ->capture_default_str();
  cmd->add_option("--report", opt->report,
                  "Also write a results page into this folder: index.html (table, previews of a successful and a failed "
                  "rollout) and index_files/ (per-episode results as LeRobot's eval_info.json); docs/results-pages.md");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] { run_evaluate(*opt, cluster); });
}

}  // namespace dicestack::cli
