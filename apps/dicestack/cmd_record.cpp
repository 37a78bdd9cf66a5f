// `dicestack record`: demonstrations from an automatic expert (docs/expert.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/memory_budget.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/record.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct RecordOptions {
  WorldOption world;
  std::string expert = "mpc";
  int episodes = 100;
  std::uint64_t seed = 0;
  std::filesystem::path out;
  std::filesystem::path demos;  // the tracker's recordings
  int threads = 0;
  double noise = 0.0;
  std::string perturb = "none";
  std::string controller = "cup";
  std::string expert_feedback = "world";
  std::string estimator = "none";
  TrackerOption tracker;
  bool successes_only = false, no_replan = false, retry = false;
  bool json = false;
};

// Episodes recorded (and held) at a time.
constexpr int kRecordBatch = 256;
// The paths the printed line names, best-ranked first (the set's provenance names them all).
constexpr std::size_t kShownPaths = 3;

// How the set was made, for its meta.json: the command's options and what they mean.
std::string record_provenance(const RecordOptions& opt, const Perturbation& perturbation, const std::string& recordings) {
  const bool sensed = opt.expert_feedback == "observations";
  return "dicestack record --expert " + opt.expert + " --episodes " + std::to_string(opt.episodes) + " --seed " +
         std::to_string(opt.seed) + (opt.successes_only ? " --successes-only" : "") + (opt.no_replan ? " --no-replan" : "") +
         (opt.retry ? " --retry" : "") + (opt.noise > 0.0 ? " --noise " + std::to_string(opt.noise) : "") +
         (opt.perturb == "none" ? "" : " --perturb " + opt.perturb) + (sensed ? " --expert-feedback observations" : "") +
         (opt.controller == "cup" ? "" : " --controller " + opt.controller) +
         (opt.estimator == "none" ? "" : " --estimator " + opt.estimator) +
         (opt.world.start == "random" ? "" : " --start " + opt.world.start) +
         (opt.demos.empty() ? "" : " --demos " + opt.demos.string()) + opt.tracker.as_arguments() +
         "; episode i starts from random_start_state(world, training_start_seed(seed, i))" + recordings +
         (opt.noise > 0.0 ? "; DART noise: executed actions perturbed by Gaussian noise of std " + std::to_string(opt.noise) +
                                (opt.controller == "cup" ? " x action.scale" : " x the torque limit") +
                                " per dimension, clean expert actions recorded"
                          : "") +
         (opt.controller == "cup" ? "" : "; the expert's cup actions told in the joint torques the cup controller held") +
         (opt.controller == "cup" || opt.expert != "tracker" ? ""
                                                             : " (in joint torques its paths are ranked from 32 probe starts "
                                                               "unless --tracker probes=N, and refined only with --tracker refine=N)") +
         (perturbation.nominal() ? "" : "; domain randomisation: each episode in its own world drawn from its seed (" +
                                            perturbation_summary(perturbation) + ")") +
         (sensed ? "; the expert's feedback acted on " +
                       std::string(opt.estimator == "none" ? "the observations" : "the " + opt.estimator + " estimator's estimate") +
                       ", the states recorded are the world's"
                 : "");
}

// The tracker's recordings, ranked by simulations of what it will answer. Adds to `provenance`
// the set they came from and their ranking, and says which paths lead before the episodes
// (which path the expert plays decides what a student of the set learns).
std::shared_ptr<const Recordings> tracker_recordings(const RecordOptions& opt, const WorldConfig& world,
                                                     ActionKind controller, Cluster& cluster, std::string& provenance,
                                                     std::string& followed) {
  if (opt.demos.empty()) throw ConfigError("record: --expert tracker follows recordings: give them with --demos DIR|builtin|human");
  const auto dir = resolve_demo_set(opt.demos, world);
  const DemoSet demos = read_demo_set(dir);
  auto recordings = make_recordings(demos.episodes, world, opt.tracker.config_for(controller), opt.seed, opt.threads, cluster);
  provenance = "; recordings followed: the " + std::to_string(demos.episodes.size()) + " episodes of " + dir.string() +
               " (" + (demos.description.empty() ? "no description" : demos.description) + "), ranked " +
               followed_recordings(*recordings);
  followed = followed_recordings(*recordings, kShownPaths);
  if (cluster.is_root() && !opt.json) print_line("the tracker follows " + followed);
  return recordings;
}

int run_record(const RecordOptions& opt, Cluster& cluster) {
  check_demo_set_replaceable(opt.out);  // refuse a user's folder before any work
  const WorldConfig world = opt.world.load();
  const Perturbation perturbation = load_perturbation(opt.perturb, world);  // before any work
  RecordRequest request;
  request.perturbation = perturbation;
  request.feedback = opt.expert_feedback == "observations" ? ExpertFeedback::observations : ExpertFeedback::world;
  request.estimator = estimator_config(opt.estimator);
  const auto t0 = std::chrono::steady_clock::now();
  ExpertConfig expert;
  expert.replan = !opt.no_replan;
  expert.retry = opt.retry;
  expert.controller = controller_kind(opt.controller);
  check_record_request(expert.controller, world, request);
  std::string recordings;  // for the provenance
  std::string followed;    // the tracker's paths, best-ranked first
  if (opt.expert == "tracker") {
    expert.recordings = tracker_recordings(opt, world, expert.controller, cluster, recordings, followed);
  } else if (!opt.demos.empty()) {
    throw ConfigError("record: --demos gives the recordings of --expert tracker; expert " + opt.expert + " reads none");
  } else if (opt.tracker.given()) {
    throw ConfigError("record: --tracker-preset and --tracker set --expert tracker; expert " + opt.expert + " has neither");
  }
  request.seed = opt.seed;
  request.threads = opt.threads;
  request.noise = expert.controller == ActionKind::cup ? Action{opt.noise, opt.noise, opt.noise}
                                                      : Action::torques({opt.noise, opt.noise, opt.noise, opt.noise});
  // What the set holds of each episode until the end (its meta.json entry): the only part of a
  // recording that grows with the count.
  require_memory("recording", static_cast<std::uint64_t>(opt.episodes), kEpisodeEntryBytes, "episodes");
  DemoSet header;
  header.world = world;
  header.description = "dicestack record --expert " + opt.expert + (opt.demos.empty() ? "" : " --demos " + opt.demos.string()) +
                       opt.tracker.as_arguments();
  header.provenance = record_provenance(opt, perturbation, recordings);
  int success = 0, stacked = 0, walls = 0;
  double cup = 0.0;
  // Batches of kRecordBatch episodes, each written as it comes and dropped: memory stays that
  // of one batch whatever the count (the episodes and their order are the same as in one go).
  const auto record_all = [&](const EpisodeSink& keep) {
    for (int first = 0; first < opt.episodes; first += kRecordBatch) {
      request.first = static_cast<std::uint64_t>(first);
      request.episodes = std::min(kRecordBatch, opt.episodes - first);
      for (const Episode& e : record_expert(opt.expert, expert, world, request, cluster)) {  // collective
        success += e.outcome.realistic_success();
        stacked += e.outcome.stacked;
        walls += e.outcome.wall_contact;
        cup += e.outcome.dice_in_cup;
        if (!opt.successes_only || e.outcome.realistic_success()) keep(e);
      }
    }
  };
  // Every rank makes the same record_expert calls (one per batch, from opt.episodes alone). If
  // the root fails while writing, it stops making them; the run does not hang because a failure
  // on any rank ends every rank (MPI_Abort in main.cpp).
  if (!cluster.is_root()) {  // the root writes and prints
    record_all([](const Episode&) {});
    return 0;
  }
  const std::size_t written = write_demo_set_streaming(header, opt.out, record_all);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double n = std::max(1, opt.episodes);
  if (opt.json) {
    print_line(nlohmann::json{{"expert", opt.expert},
                              {"episodes", opt.episodes},
                              {"written", written},
                              {"realistic_success_rate", success / n},
                              {"stacked_rate", stacked / n},
                              {"dice_in_cup_mean", cup / n},
                              {"wall_contact_rate", walls / n},
                              {"seconds_per_episode", seconds / n},
                              {"seconds", seconds},
                              {"out", opt.out.string()},
                              {"tracker_followed", followed.empty() ? nlohmann::json(nullptr) : nlohmann::json(followed)}}
                   .dump());
    return 0;
  }
  char line[400];
  std::snprintf(line, sizeof line,
                "expert %s, %d episodes from seed %llu: realistic success %.1f%%, stacked %.1f%%, dice in cup %.2f, "
                "wall contact %.1f%%; %.3f s per episode (%.1f s)\nwrote %zu episodes to %s",
                opt.expert.c_str(), opt.episodes, static_cast<unsigned long long>(opt.seed), 100 * success / n,
                100 * stacked / n, cup / n, 100 * walls / n, seconds / n, seconds, written,
                opt.out.string().c_str());
  print_line(line);
  return 0;
}

}  // namespace

void add_record_command(CLI::App& app, Cluster& cluster) {
  auto opt = std::make_shared<RecordOptions>();
  std::string experts;
  for (const auto& e : expert_list()) experts += "\n  " + e.name + ": " + e.description;
  CLI::App* cmd = app.add_subcommand("record", "Record demonstrations from an automatic expert:" + experts);
  opt->world.add_to(*cmd, true);
  cmd->add_option("--expert", opt->expert, "Expert name")->capture_default_str();
  cmd->add_option("--episodes", opt->episodes, "Episodes from random starts")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Seed of the starts")->check(seed_check())->capture_default_str();
  cmd->add_option("--out", opt->out, "Demonstration folder to write (missing, empty, or a dicestack set, which is replaced whole)")->required();
  cmd->add_option("--demos", opt->demos,
                  "tracker: the recordings it follows (a demonstration folder, builtin or human)");
  opt->tracker.add_to(*cmd);
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->check(threads_check())->capture_default_str();
  cmd->add_option("--perturb", opt->perturb,
                  "Domain randomisation: each episode in its own perturbed world, drawn from its seed: none, easy, "
                  "medium, hard or a perturbation file (docs/robustness.md)")
      ->capture_default_str();
  add_expert_controller_option(*cmd, opt->controller)
      ->description("What the expert answers on the arm: cup (the cup's velocity change) or joint_torque (its cup actions "
                    "told in the joint torques the cup controller held; the set keeps them as its actions)");
  cmd->add_option("--expert-feedback", opt->expert_feedback,
                  "What the expert's feedback acts on: world (its own privilege) or observations (what a policy is "
                  "shown under the perturbation's sensing factors, or with --estimator the estimate; its choices "
                  "still read the world). The states recorded are the world's either way")
      ->check(CLI::IsMember({"world", "observations"}))
      ->capture_default_str();
  add_estimator_option(*cmd, opt->estimator)
      ->description("With --expert-feedback observations, what stands between the sensors and the expert: none (the "
                    "observations), kalman or particle[:N] (docs/robustness.md)")
      ->capture_default_str();
  cmd->add_option("--noise", opt->noise,
                  "DART: std of Gaussian noise added to each executed action, as a fraction of action.scale (with "
                  "--controller joint_torque: of each torque limit); the "
                  "expert's clean actions are recorded")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  cmd->add_flag("--no-replan", opt->no_replan,
                "mpc: choose the plan once, from the start, and never replan (its actions are then a function of "
                "the start, the step and the state)");
  cmd->add_flag("--retry", opt->retry,
                "mpc and tracker: once a failed attempt has come to rest, start afresh from there (a new plan, a "
                "path chosen anew), as the +retry feature maps expect");
  cmd->add_flag("--successes-only", opt->successes_only, "Keep only realistic successes");
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt, &cluster] { run_record(*opt, cluster); });
}

}  // namespace dicestack::cli
