// `dicestack train`: a learner turns demonstrations and a regressor into a model file.
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/experiments/train.hpp>
#include <dicestack/regressors/model.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct TrainOptions {
  WorldOption world;
  DemosOption demos;
  std::string regressor, learner = "bc", split = "episodes", features, controller;
  std::vector<std::string> sets, options;
  std::filesystem::path out, checkpoint;
  std::uint64_t seed = 0;
  int threads = 0;
  bool json = false, resume = false;
};

int run_train(const TrainOptions& opt, Cluster& cluster) {
  const WorldConfig world = opt.world.load();
  check_replaceable(opt.out, model_ownership());  // refuse a user's file before any work
  TrainRequest request;
  request.world = world;
  request.regressor = opt.regressor;
  request.regressor_sets = opt.sets;
  request.learner = opt.learner;
  request.learner_options = opt.options;
  request.features = opt.features;
  request.controller = opt.controller;
  request.split = opt.split;
  request.seed = opt.seed;
  request.threads = opt.threads;
  request.checkpoint_dir = opt.checkpoint.empty() ? std::filesystem::path(opt.out.string() + ".checkpoint") : opt.checkpoint;
  request.resume = opt.resume;
  request.cluster = &cluster;
  check_train_settings(request);  // every name and option, before the demonstrations are read
  const auto dir = opt.demos.resolve(world, cluster);
  request.demos = read_demo_set(dir).episodes;
  request.demos_name = dir.string();
  ProgressBar bar;
  request.progress = [&](const Progress& p) {
    bar.update(p.fraction, progress_text(opt.learner + " " + opt.regressor, p));
  };
  const TrainReport r = train_model(request);
  bar.finish();
  if (!cluster.is_root()) return 0;  // the root writes and prints
  save_model(*r.result.model, opt.out);
  const std::filesystem::path curve_path = opt.out.string() + ".curve.csv";
  if (!r.result.curve.empty()) write_curve_csv(r.result.curve, curve_path);
  const auto& record = r.result.model->record;
  if (opt.json) {
    nlohmann::json j{{"model", opt.out.string()}, {"learner", opt.learner}, {"regressor", opt.regressor},
                     {"features", r.features},    {"seconds", r.seconds}};
    if (r.score) j["train_error"] = r.score->train_error;
    if (r.score && r.score->test_error) j["test_error"] = *r.score->test_error;
    if (!r.result.curve.empty()) j["curve"] = curve_path.string();
    if (record.contains("tracker_followed")) j["tracker_followed"] = record.at("tracker_followed");
    print_line(j.dump());
  } else {
    std::string errors;  // a torque policy has none: the recordings hold cup actions
    if (r.score) {
      char train[64];
      std::snprintf(train, sizeof train, ": train error %.3f", r.score->train_error);
      errors = train;
    }
    if (r.score && r.score->test_error) errors += ", test error " + std::to_string(*r.score->test_error).substr(0, 5);
    char line[256];
    std::snprintf(line, sizeof line, "trained %s with %s in %.2f s%s -> %s", opt.regressor.c_str(), opt.learner.c_str(),
                  r.seconds, errors.c_str(), opt.out.string().c_str());
    print_line(line);
    // Which recording a policy from recordings plays, and how robust the ranking found it:
    // what to look at first when a policy from a few recordings stacks rarely.
    if (record.contains("tracker_followed")) print_line("  the demonstrator followed " + record.at("tracker_followed"));
    if (record.contains("dart_expert_successes"))
      print_line("  dart: the expert succeeded in " + record.at("dart_expert_successes") + " of " +
                 record.at("dart_episodes") + " noisy episodes");
  }
  return 0;
}

}  // namespace

void add_train_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<TrainOptions>();
  CLI::App* cmd = app.add_subcommand("train", "Train a policy: a learner fits a regressor to demonstrations");
  opt->world.add_to(*cmd, true);
  opt->demos.add_to(*cmd);
  cmd->add_option("--regressor", opt->regressor, "Regressor name (see `dicestack regressors`)")->required();
  cmd->add_option("--set", opt->sets, "key=value parameter of the regressor; repeatable");
  cmd->add_option("--learner", opt->learner, "Learner: bc, dagger, dad, dart (see `dicestack learners`)")->capture_default_str();
  cmd->add_option("--option", opt->options, "key=value option of the learner; repeatable");
  cmd->add_option("--features", opt->features,
                  "Feature map the policy reads, a name of parts such as state+clock+start_state or "
                  "state+clock+start_state@dice+retry/position (default: the learner's; the grammar: `dicestack "
                  "learners`, docs/reference/learners.md)");
  cmd->add_option("--controller", opt->controller,
                  "What the policy's actions drive: cup (velocity changes; on the arm through its operational-space "
                  "controller) or joint_torque (the arm's four torques: dart, dagger, dad with starts=training and corrector=track, or bc on a set recorded on the arm in them, with --embodiment arm; the default "
                  "map then reads the arm's links and answers the cup pose and the posture's acceleration that operational-space control turns into the torques: /osc). Default: what the feature map answers")
      ->check(CLI::IsMember({"cup", "joint_torque"}));
  cmd->add_option("--split", opt->split,
                  "episodes: train on episodes i % 5 != 4, report test error and give the rest to learners as "
                  "held-out demonstrations; none: all")
      ->check(CLI::IsMember({"episodes", "none"}))
      ->capture_default_str();
  cmd->add_option("--out", opt->out, "Model file to write")->required();
  cmd->add_option("--seed", opt->seed, "Seed of every random choice")->check(seed_check())->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--checkpoint", opt->checkpoint,
                  "Folder for an iterative learner's checkpoints (default: MODEL.checkpoint); kept after the run");
  cmd->add_flag("--resume", opt->resume, "Continue from the checkpoint's last finished iteration");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] { run_train(*opt, cluster); });
}

}  // namespace dicestack::cli
