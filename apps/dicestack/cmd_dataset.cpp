// `dicestack import cupdice` and `dicestack dataset info|validate|view`: getting demonstrations
// in, and looking at them (robomimic and Minari: cmd_interop.cpp).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/cupdice_import.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/experiments/learning_curve.hpp>
#include <dicestack/pages/dataset_viewer.hpp>
#include <dicestack/pages/page.hpp>
#include <dicestack/experiments/train.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct ImportOptions {
  WorldOption world;
  std::filesystem::path src, out;
};

struct DatasetOptions {
  std::filesystem::path dir;
  bool json = false;
};

struct ViewOptions {
  WorldOption world;
  std::filesystem::path set, out;
};

struct SubsetOptions {
  WorldOption world;
  std::filesystem::path set, out;
  int recordings = 3;
  std::uint64_t seed = 0;
};

// The recordings a learning curve's draw trains on, as a set of their own.
int run_subset(const SubsetOptions& opt) {
  check_demo_set_replaceable(opt.out);  // before any work
  const auto folder = resolve_demo_set(opt.set, opt.world.load());
  DemoSet set = read_demo_set(folder);
  set.episodes = draw_recordings(set.episodes, opt.recordings, opt.seed);
  std::string names;
  for (const auto& e : set.episodes) names += (names.empty() ? "" : ", ") + e.name;
  set.provenance = "dicestack dataset subset " + opt.set.string() + " --recordings " + std::to_string(opt.recordings) +
                   " --seed " + std::to_string(opt.seed) + ": " + names + " of " + folder.string() +
                   (set.provenance.empty() ? "" : "; that set: " + set.provenance);
  write_demo_set(set, opt.out);
  print_line("wrote " + std::to_string(set.episodes.size()) + " recordings to " + opt.out.string() + ": " + names);
  return 0;
}

int run_view(const ViewOptions& opt) {
  const DemoSet set = read_demo_set(resolve_demo_set(opt.set, opt.world.load()));
  write_dataset_viewer(set, opt.set.string(), opt.out);
  print_line("wrote " + opt.out.string() + " (" + std::to_string(set.episodes.size()) + " episodes; their data in " +
             page_media_folder(opt.out).string() + ")");
  return 0;
}

int run_import(const ImportOptions& opt) {
  const DemoSet set = import_cupdice(opt.src, opt.world.load());
  write_demo_set(set, opt.out);
  std::size_t frames = 0, stacked = 0, success = 0;
  for (const auto& e : set.episodes) {
    frames += e.size();
    stacked += e.outcome.stacked;
    success += e.outcome.realistic_success();
  }
  char line[256];
  std::snprintf(line, sizeof line, "imported %zu recordings (%zu frames) into %s: %zu stacked, %zu realistic successes",
                set.episodes.size(), frames, opt.out.string().c_str(), stacked, success);
  print_line(line);
  return 0;
}

int run_info(const DatasetOptions& opt) {
  const DemoSet set = read_demo_set(opt.dir);
  // The columns' ranges: the states and the actions, the cup's or (an arm's episodes in joint
  // torques) the torques.
  const ActionKind kind = set.episodes.empty() ? ActionKind::cup : set.episodes.front().actions.front().kind();
  const Dataset all = make_dataset(set.episodes, feature_map(kind == ActionKind::cup ? "state" : "state/torque"));
  std::map<std::string, std::size_t> sources;
  std::size_t stacked = 0, success = 0, walls = 0, in_cup = 0, shortest = SIZE_MAX, longest = 0, transitions = 0;
  for (const auto& e : set.episodes) {
    transitions += e.has_transitions();
    stacked += e.outcome.stacked;
    success += e.outcome.realistic_success();
    walls += e.outcome.wall_contact;
    in_cup += static_cast<std::size_t>(e.outcome.dice_in_cup);
    shortest = std::min(shortest, e.size());
    longest = std::max(longest, e.size());
    for (auto s : e.sources) ++sources[std::string(to_string(s))];
  }
  const double n = static_cast<double>(set.episodes.size());
  if (opt.json) {
    nlohmann::json columns = nlohmann::json::object();
    const auto names = episode_csv_columns(kDemoFormatVersion, kind);
    for (Eigen::Index j = 0; j < all.x.cols(); ++j)
      columns[names[static_cast<std::size_t>(j) + 1]] = {{"min", all.x.col(j).minCoeff()}, {"max", all.x.col(j).maxCoeff()}};
    for (Eigen::Index j = 0; j < all.y.cols(); ++j)
      columns[names[kStateDim + 1 + static_cast<std::size_t>(j)]] = {{"min", all.y.col(j).minCoeff()},
                                                                     {"max", all.y.col(j).maxCoeff()}};
    print_line(nlohmann::json{{"episodes", set.episodes.size()},
                              {"frames", all.rows()},
                              {"stacked", stacked},
                              {"realistic_success", success},
                              {"wall_contact", walls},
                              {"dice_in_cup_mean", in_cup / n},
                              {"sources", sources},
                              {"with_transitions", transitions},
                              {"columns", columns},
                              {"description", set.description}}
                   .dump());
    return 0;
  }
  char line[512];
  std::snprintf(line, sizeof line,
                "%s\n  %s\n  episodes %zu, frames %zu (%zu to %zu per episode, %.1f s to %.1f s)\n"
                "  outcomes: stacked %zu, realistic success %zu, wall contact %zu, dice in cup (most) mean %.2f",
                opt.dir.string().c_str(), set.description.c_str(), set.episodes.size(), all.rows(), shortest, longest,
                shortest * set.world.physics.control_dt, longest * set.world.physics.control_dt, stacked, success, walls,
                in_cup / n);
  print_line(line);
  std::string src = "  sources:";
  for (const auto& [name, count] : sources) src += " " + name + " " + std::to_string(count);
  print_line(src);
  print_line("  final state, rewards and end flags (format v2): " + std::to_string(transitions) + " of " +
             std::to_string(set.episodes.size()) + " episodes");
  print_line("  column            min          max");
  const auto names = episode_csv_columns(kDemoFormatVersion, kind);
  for (Eigen::Index j = 0; j < all.x.cols() + all.y.cols(); ++j) {
    const bool is_x = j < all.x.cols();
    const auto col = is_x ? all.x.col(j) : all.y.col(j - all.x.cols());
    std::snprintf(line, sizeof line, "  %-12s %12.4f %12.4f", names[static_cast<std::size_t>(j) + 1].c_str(),
                  col.minCoeff(), col.maxCoeff());
    print_line(line);
  }
  return 0;
}

int run_validate(const DatasetOptions& opt) {
  const DemoSet set = read_demo_set(opt.dir);
  std::size_t frames = 0;
  for (const auto& e : set.episodes) frames += e.size();
  print_line(opt.dir.string() + ": valid (" + std::to_string(set.episodes.size()) + " episodes, " +
             std::to_string(frames) + " frames)");
  return 0;
}

struct LoadBenchOptions {
  WorldOption world;
  DemosOption demos;
  int repeats = 9;
  bool json = false;
};

// Reading a whole set (every file checked) and stacking X and Y; median of `repeats` runs.
int run_bench_load(const LoadBenchOptions& opt) {
  const auto dir = opt.demos.path.empty() ? human_demo_set(opt.world.load()) : opt.demos.resolve(opt.world.load());
  std::vector<double> seconds;
  std::size_t rows = 0, episodes = 0;
  for (int r = 0; r < opt.repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const DemoSet set = read_demo_set(dir);
    const Dataset d = make_dataset(set.episodes);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    rows = d.rows();
    episodes = d.episodes();
  }
  std::sort(seconds.begin(), seconds.end());
  const double median = seconds[seconds.size() / 2];
  if (opt.json) {
    print_line(nlohmann::json{{"demos", dir.string()}, {"episodes", episodes}, {"rows", rows}, {"load_s", median},
                              {"rows_per_s", rows / median}, {"repeats", opt.repeats}}
                   .dump());
    return 0;
  }
  char line[256];
  std::snprintf(line, sizeof line, "bench load: %s: %zu episodes, %zu rows read, checked and stacked in %.3f s (median of %d; %.0f rows/s)",
                dir.string().c_str(), episodes, rows, median, opt.repeats, rows / median);
  print_line(line);
  return 0;
}

}  // namespace

void add_bench_load_command(CLI::App& bench) {
  auto opt = std::make_shared<LoadBenchOptions>();
  CLI::App* cmd = bench.add_subcommand("load", "Time to read a demonstration set and build X and Y");
  opt->world.add_to(*cmd);
  opt->demos.add_to(*cmd);
  cmd->add_option("--repeats", opt->repeats, "Runs (the median is reported)")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_bench_load(*opt); });
}

void add_dataset_commands(CLI::App& app) {
  CLI::App* import = app.add_subcommand("import", "Convert recordings from other tools into dicestack's format");
  import->require_subcommand(1);
  auto imp = std::make_shared<ImportOptions>();
  CLI::App* cupdice = import->add_subcommand("cupdice", "The paper's original recordings (both layouts)");
  cupdice->add_option("src", imp->src, "Folder of imitate_*.csv files (searched recursively)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cupdice->add_option("--out", imp->out, "Folder to write the demonstration set to (missing, empty, or a dicestack set, which is replaced whole)")->required();
  imp->world.add_to(*cupdice);
  cupdice->callback([imp] { run_import(*imp); });

  CLI::App* dataset = app.add_subcommand("dataset", "Inspect, check and export demonstration sets");
  dataset->require_subcommand(1);
  auto info = std::make_shared<DatasetOptions>();
  CLI::App* cmd = dataset->add_subcommand("info", "Summary: episodes, frames, outcomes, per-column ranges");
  cmd->add_option("dir", info->dir, "Demonstration folder")->required();
  cmd->add_flag("--json", info->json, "Print one JSON object");
  cmd->callback([info] { run_info(*info); });
  auto check = std::make_shared<DatasetOptions>();
  cmd = dataset->add_subcommand("validate", "Check every file of a set; exit 1 with the first problem");
  cmd->add_option("dir", check->dir, "Demonstration folder")->required();
  cmd->callback([check] { run_validate(*check); });
  auto view = std::make_shared<ViewOptions>();
  cmd = dataset->add_subcommand("view", "An episode browser: a page that plays each episode beside plots of its states and actions");
  view->world.add_to(*cmd);
  cmd->add_option("set", view->set, "Demonstration folder, builtin or human")->required();
  cmd->add_option("--out", view->out, "The page, PAGE.html; the episodes' data go to PAGE_files/ beside it")->required();
  cmd->callback([view] { run_view(*view); });
  auto subset = std::make_shared<SubsetOptions>();
  cmd = dataset->add_subcommand("subset",
                                "A few recordings of a set drawn at random, as `leaderboard --recordings` draws them");
  subset->world.add_to(*cmd);
  cmd->add_option("set", subset->set, "Demonstration folder, builtin or human")->required();
  cmd->add_option("--recordings", subset->recordings, "How many to draw (all of them: the whole set)")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  cmd->add_option("--seed", subset->seed, "Seed of the draw")->check(seed_check())->capture_default_str();
  cmd->add_option("--out", subset->out, "The new set's folder")->required();
  cmd->callback([subset] { run_subset(*subset); });
  add_interop_commands(*import, *dataset);
}

}  // namespace dicestack::cli
