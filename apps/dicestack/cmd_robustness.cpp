// `dicestack robustness`: a model's or an expert's realistic success in perturbed worlds, factor
// by factor and level by level (docs/robustness.md). The work is the library's
// (learners/robustness.hpp): this parses, calls it and prints.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/experiments/robustness.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct RobustnessOptions {
  WorldOption world;
  std::filesystem::path model, demos, out;
  std::string expert, format = "md", expert_feedback = "world", controller = "cup";
  std::string estimator;  // empty: the model's own, none for an expert
  int episodes = 100;
  std::uint64_t seed = 0;
  int threads = 0;
  std::vector<std::string> factors;
  TrackerOption tracker;
};

// Joint torques run on the arm. `what` names who answers in them.
void check_arm(const std::string& what, const WorldConfig& world) {
  if (world.embodiment != Embodiment::arm) throw ConfigError(what + " drives an arm's joints: give --embodiment arm");
}

// An expert in joint torques runs without an estimator: its feedback is turned into torques
// through the world's own links, not an estimate's.
void check_torque_run(const std::string& what, const RobustnessOptions& opt, const WorldConfig& world) {
  check_arm(what, world);
  if (!opt.estimator.empty() && opt.estimator != "none")
    throw ConfigError(what + ": an expert in joint torques turns its feedback into torques through the world's own links; leave --estimator out");
}

// An expert in joint torques (a model answers in its own actions).
void check_controller(const RobustnessOptions& opt, const WorldConfig& world) {
  if (opt.controller == "cup") return;
  const std::string what = "robustness: --controller " + opt.controller;
  if (opt.expert.empty()) throw ConfigError(what + " is for --expert NAME (a model answers in its own actions)");
  check_torque_run(what, opt, world);
}

// Every option that does not need a file read, checked before any work.
void check_options(const RobustnessOptions& opt, const WorldConfig& world) {
  if (opt.model.empty() == opt.expert.empty()) throw ConfigError("robustness: give one of --model M or --expert NAME");
  if (!opt.demos.empty() && opt.expert != "tracker")
    throw ConfigError("robustness: --demos gives the recordings of --expert tracker");
  if (opt.tracker.given() && opt.expert != "tracker")
    throw ConfigError("robustness: --tracker-preset and --tracker set --expert tracker");
  check_controller(opt, world);
  const bool sensed = opt.expert_feedback == "observations";
  if (sensed && opt.expert.empty()) throw ConfigError("robustness: --expert-feedback is for --expert NAME (a model acts on the observations)");
  check_robustness_factors(opt.factors);
  if (!opt.estimator.empty() && opt.estimator != "none" && !opt.expert.empty() && !sensed)
    throw ConfigError("robustness: --estimator stands between the sensors and the policy: with --expert it needs "
                      "--expert-feedback observations (the expert's own feedback reads the world)");
  {
    EvalRequest rows;  // the rollouts' count, checked before any recordings are read
    rows.episodes = opt.episodes;
    rows.threads = opt.threads;
    check_evaluation(world, rows);
  }
}

void run_robustness(const RobustnessOptions& opt, Cluster& cluster) {
  const WorldConfig world = opt.world.load();
  check_options(opt, world);
  const bool sensed = opt.expert_feedback == "observations";
  if (!opt.out.empty() && cluster.is_root()) check_robustness_out(opt.out, opt.format);  // before any work
  PolicyFactory factory;
  RobustnessRun run;
  run.world = opt.world.path.empty() ? "default" : opt.world.path.string();
  run.episodes = opt.episodes;
  run.seed = opt.seed;
  RobustnessRequest request;
  request.episodes = opt.episodes;
  request.seed = opt.seed;
  request.threads = opt.threads;
  request.factors = opt.factors;
  run.estimator = opt.estimator.empty() ? "none" : opt.estimator;
  if (!opt.model.empty()) {
    auto model = std::make_shared<const Model>(load_model(opt.model));
    check_map_world(model->features(), world);
    if (model->features().action_kind() == ActionKind::joint_torque)
      check_arm("robustness: " + opt.model.string() + " (a policy in joint torques)", world);
    run.estimator = estimator_for(opt.estimator, *model);
    request.actions = model->features().action_kind();
    factory = [model] { return std::make_unique<ModelPolicy>(model); };
    run.policy = "model " + opt.model.string() + " (" + model->regressor().name() + ", " + model->features().name() + ")";
    run.record = model->record;
  } else {
    ExpertConfig config;
    config.controller = controller_kind(opt.controller);
    if (opt.expert == "tracker") {
      if (opt.demos.empty()) throw ConfigError("robustness: --expert tracker follows recordings: give them with --demos");
      const TrackerConfig tracker = opt.tracker.config_for(config.controller);  // simulating what it will answer
      config.recordings = make_recordings(read_demo_set(resolve_demo_set(opt.demos, world)).episodes, world, tracker,
                                          opt.seed, opt.threads, cluster);
    }
    make_expert(opt.expert, config);  // an unknown name fails here, before any row
    const ExpertFeedback feedback = sensed ? ExpertFeedback::observations : ExpertFeedback::world;
    factory = [name = opt.expert, config, feedback] { return std::make_unique<OwnedExpertPolicy>(make_expert(name, config), feedback); };
    run.policy = "expert " + opt.expert + (opt.demos.empty() ? "" : " (recordings " + opt.demos.string() + ")") +
                 opt.tracker.as_arguments() + (opt.controller == "cup" ? "" : ", in joint torques") +
                 (sensed ? ", feedback on the observations" : "");
    request.reads_world = !sensed;
    request.actions = config.controller;
  }
  request.estimator = estimator_config(run.estimator);
  run.reads_world = request.reads_world;
  if (cluster.is_root())
    request.progress = [&](int row, int rows, const std::string& factor, const std::string& level) {
      std::cerr << "[" << row + 1 << "/" << rows << "] " << factor << " " << level << '\n' << std::flush;
    };
  const RobustnessTable table = robustness_table(robustness(factory, world, request, cluster), run);
  if (!cluster.is_root()) return;
  const RobustnessFormat& format = robustness_format(opt.format);
  // A page is for the file; the terminal gets its Markdown (as the leaderboard's html does).
  const bool echo = !opt.out.empty() && !format.echo.empty();
  std::cout << render_robustness(table, echo ? format.echo : format.name) << std::flush;
  if (!opt.out.empty()) {
    write_robustness(table, opt.format, opt.out);
    std::cout << "wrote " << opt.out.string() << '\n' << std::flush;
  }
}

std::vector<std::string> robustness_format_names(std::string* help) {
  std::vector<std::string> names;
  for (const RobustnessFormat& f : robustness_formats()) {
    names.push_back(f.name);
    *help += (help->empty() ? "" : "; ") + f.name + ": " + f.description;
  }
  return names;
}

}  // namespace

void add_robustness_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<RobustnessOptions>();
  CLI::App* cmd = app.add_subcommand("robustness", "A model's or an expert's success in perturbed worlds, factor x level");
  opt->world.add_to(*cmd, true);
  cmd->add_option("--model", opt->model, "Model file written by `dicestack train`")->check(CLI::ExistingFile);
  cmd->add_option("--expert", opt->expert, "An automatic expert instead: scripted, mpc or tracker (with --demos)");
  cmd->add_option("--demos", opt->demos, "tracker: the recordings it follows (a folder, builtin or human)");
  opt->tracker.add_to(*cmd);
  add_expert_controller_option(*cmd, opt->controller);
  cmd->add_option("--expert-feedback", opt->expert_feedback,
                  "What the expert's feedback acts on: world (its own privilege; the sensing factors are left out) or "
                  "observations (what a policy is shown; its choices still read the world)")
      ->check(CLI::IsMember({"world", "observations"}))
      ->capture_default_str();
  add_estimator_option(*cmd, opt->estimator);
  cmd->add_option("--episodes", opt->episodes, "Rollouts per row")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the starts and the draws")->check(seed_check())->capture_default_str();
  cmd->add_option("--factors", opt->factors,
                  "Only these rows, comma-separated: none (nominal), all (every factor at once) or factor names (default: every one)")
      ->delimiter(',');
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  std::string formats_help;
  const std::vector<std::string> formats = robustness_format_names(&formats_help);
  cmd->add_option("--format", opt->format, formats_help)->check(CLI::IsMember(formats))->capture_default_str();
  cmd->add_option("--out", opt->out,
                  "Also write the table to this file (atomically; only a table of ours, or for html a page of ours, is "
                  "replaced)");
  cmd->callback([opt, &cluster] { run_robustness(*opt, cluster); });
}

}  // namespace dicestack::cli
