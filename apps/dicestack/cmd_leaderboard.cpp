// `dicestack leaderboard`: the paper's Table I regenerated: every regressor under every
// learner, with train and test error (eq. 9), rollout outcomes with 95% intervals, fit time and
// time per step. Interrupted runs resume from <out>.partial.json. The work is the library's
// run_leaderboard (learners/leaderboard.hpp), shared with the Python package.
#include <algorithm>
#include <iostream>

#include <dicestack/experiments/baseline.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/experiments/learning_curve.hpp>
#include <dicestack/experiments/profile.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct LeaderboardOptions {
  WorldOption world;
  DemosOption demos;
  LeaderboardRequest request;
  std::string controller = "cup";
  std::vector<int> recordings;  // --recordings: a learning curve instead of the table
  int draws = 3;
};

// `--recordings 1,3,10`: realistic success against the number of recordings (learning_curve.hpp).
int run_curve(const LeaderboardOptions& opt, CLI::App& cmd, Cluster& cluster) {
  for (const char* unused : {"--baselines", "--features", "--seeds", "--profile", "--split", "--perturb", "--estimator", "--controller"})
    if (cmd.count(unused) > 0) throw ConfigError(std::string("leaderboard --recordings draws a learning curve; ") + unused + " is for the table");
  const LeaderboardRequest& t = opt.request;
  const auto formats = learning_curve_formats();
  if (std::find(formats.begin(), formats.end(), t.format) == formats.end())
    throw ConfigError("leaderboard --recordings: --format must be md, csv, json or html, got " + t.format);
  if (!t.out.empty()) check_learning_curve_replaceable(t.out);
  LearningCurveRequest r;
  r.world = opt.world.load();
  r.demos = opt.demos.resolve(r.world, cluster);
  r.recordings = opt.recordings;
  r.draws = opt.draws;
  r.learners = t.learners;
  r.regressors = t.regressors;
  r.options = t.options;
  r.episodes = t.episodes > 0 ? t.episodes : 100;
  r.seed = t.seed;
  r.threads = t.threads;
  r.cluster = &cluster;
  const LearningCurve curve = run_learning_curve(r, [](const std::string& text) { print_progress(text); });
  if (!cluster.is_root()) return 0;
  if (!t.out.empty()) write_learning_curve(curve, t.format, t.out);
  std::cout << render_learning_curve(curve, t.out.empty() ? t.format : "md") << (t.out.empty() ? "" : "wrote " + t.out.string() + "\n")
            << std::flush;
  return 0;
}

int run_leaderboard(const LeaderboardOptions& opt, Cluster& cluster) {
  LeaderboardRequest request = opt.request;
  request.controller = controller_kind(opt.controller);
  request.world = opt.world.load();
  request.demos = opt.demos.resolve(request.world, cluster);
  request.cluster = &cluster;
  const Leaderboard board = dicestack::run_leaderboard(request, [](const LeaderboardProgress& p) {
    if (p.milestone) print_progress(p.text);
  });
  if (!cluster.is_root()) return 0;  // the root writes and prints
  if (request.out.empty()) {
    std::cout << render_leaderboard(board, request.format) << std::flush;
  } else {
    write_leaderboard(board, request.format, request.out);
    const std::string& echo = leaderboard_format(request.format).echo;
    std::cout << render_leaderboard(board, echo.empty() ? request.format : echo) << "wrote " << request.out.string() << '\n'
              << std::flush;
  }
  return 0;
}

// The --baselines and --profile help, from the registry and the profiles.
std::string baselines_help() {
  std::string names, budgets;
  for (const auto& b : baselines()) names += b.name + ", ";
  for (const auto& name : leaderboard_profile_names()) {
    const Profile& p = leaderboard_profile(name);
    budgets += (budgets.empty() ? "" : "; ") + name + ": " + std::to_string(p.optimiser_evaluations) + " evaluations (bayes " +
               std::to_string(p.bayes_evaluations) + "), " + std::to_string(p.reinforce_iterations) + " REINFORCE updates, " +
               std::to_string(p.rrt_nodes) + " RRT nodes";
  }
  return "Baselines without demonstrations as rows of their own: " + names + "or all (" + budgets + ")";
}

std::string profiles_help() {
  std::string out;
  for (const auto& name : leaderboard_profile_names())
    out += (out.empty() ? "" : ", ") + name + " (" + std::to_string(leaderboard_profile(name).rollouts) + " rollouts)";
  return out;
}

std::vector<std::string> format_names(std::string* help) {
  std::vector<std::string> names;
  for (const LeaderboardFormat& f : leaderboard_formats()) {
    names.push_back(f.name);
    *help += (help->empty() ? "" : "; ") + f.name + ": " + f.description;
  }
  return names;
}

}  // namespace

void add_leaderboard_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<LeaderboardOptions>();
  LeaderboardRequest& r = opt->request;
  CLI::App* cmd = app.add_subcommand("leaderboard", "Train every regressor under every learner and print Table I");
  opt->world.add_to(*cmd, true);
  opt->demos.add_to(*cmd);
  cmd->add_option("--regressors", r.regressors, "Regressors (comma-separated; default: all registered)")->delimiter(',');
  cmd->add_option("--learners", r.learners, "Learners (comma-separated; default: bc, dagger, dart)")->delimiter(',');
  cmd->add_option("--features", r.features,
                  "Feature maps (comma-separated): a row per learner and map it can read (default: each learner's own; "
                  "paper profile: state and dart's map for every learner that reads them)")
      ->delimiter(',');
  cmd->add_option("--option", r.options, "key=value learner option (applied to the learners that have it); repeatable");
  cmd->add_option("--baselines", r.baselines, baselines_help())->delimiter(',');
  cmd->add_option("--episodes", r.episodes, "Rollouts per row and training seed (default: 20 quick, 100 paper)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seeds", r.seeds, "Training seeds per row")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", r.seed, "First seed")->check(seed_check())->capture_default_str();
  cmd->add_option("--profile", r.profile, profiles_help())
      ->check(CLI::IsMember(leaderboard_profile_names()))
      ->capture_default_str();
  cmd->add_option("--split", r.split, "episodes (i % 5 == 4 is test) or rows (the paper's random 25% of rows)")
      ->check(CLI::IsMember({"episodes", "rows"}))
      ->capture_default_str();
  std::string formats_help;
  const std::vector<std::string> formats = format_names(&formats_help);
  cmd->add_option("--format", r.format, formats_help)->check(CLI::IsMember(formats))->capture_default_str();
  cmd->add_option("--out", r.out, "Also write the table to this file (atomically)");
  cmd->add_option("--threads", r.threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--perturb", r.perturb,
                  "Roll out in perturbed worlds: none, easy, medium, hard or a perturbation file (docs/robustness.md); "
                  "training stays nominal")
      ->capture_default_str();
  add_estimator_option(*cmd, r.estimator);
  add_controller_option(*cmd, opt->controller,
                        "What the rows' policies answer: cup (the cup's velocity changes) or joint_torque (the arm's four "
                        "torques, with --embodiment arm: each learner's map in torques; dart, dagger and dad (starts=training, "
                        "corrector=track) learn them from their experts, bc from a set recorded on the arm; default learners then dart:expert=tracker; docs/arm.md)");
  cmd->add_option("--recordings", opt->recordings,
                  "Instead of the table, a learning curve: realistic success against the number of recordings each "
                  "policy learns from (comma-separated numbers, e.g. 1,3,10,68; default learners dart:expert=tracker "
                  "and dad, regressor gbt, 100 rollouts; formats md, csv, json, html with a plot)")
      ->delimiter(',')
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--draws", opt->draws, "With --recordings: random draws of each number, seeds --seed, --seed + 1, ...")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->callback([opt, &cluster, cmd] {
    if (opt->recordings.empty()) run_leaderboard(*opt, cluster);
    else run_curve(*opt, *cmd, cluster);
  });
}

}  // namespace dicestack::cli
