// `dicestack regressors`: what the registry holds, with every parameter (STYLE 5), and
// `dicestack bench regressors`: fit time, predict_row latency, throughput and eq. 9 errors.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/score.hpp>

#include "cli.hpp"
#include "options.hpp"
#include "reference_md.hpp"

namespace dicestack::cli {
namespace {

struct ListOptions {
  bool json = false;
  bool markdown = false;
};

// Prints "--set name= type default range help" lines of a schema.
void print_params(const std::vector<ParamSpec>& params, const char* flag) {
  for (const auto& p : params) {
    std::string range;
    if (p.type == ParamType::choice) {
      for (const auto& c : p.choices) range += (range.empty() ? "" : "|") + c;
    } else if (p.type != ParamType::boolean && p.type != ParamType::text) {
      std::ostringstream os;
      os << "[" << p.min << ", " << p.max << "]";
      range = os.str();
    }
    char line[512];
    std::snprintf(line, sizeof line, "    %s %-14s %-8s default %-8s %-18s %s", flag, (p.name + "=").c_str(),
                  std::string(to_string(p.type)).c_str(), p.default_value.c_str(), range.c_str(), p.help.c_str());
    print_line(line);
  }
}

int run_learners(bool markdown) {
  if (markdown) {
    std::cout << learners_reference_markdown();
    return 0;
  }
  const auto& reg = LearnerRegistry::global();
  for (const auto& name : reg.names()) {
    const auto& i = reg.info(name);
    print_line(name + "\n    " + i.description + "\n    default --features " + i.default_features);
    print_params(i.params, "--option");
  }
  print_line("(playback is an evaluation: the leaderboard's last row replays the demonstrations)");
  print_line("\nfeature maps (--features NAME): what a learned policy's regressor reads");
  for (const auto& name : feature_map_names()) {
    if (name.find('/') != std::string::npos) continue;  // the twins are listed once, below
    const FeatureMap& m = feature_map(name);
    char line[256];
    std::snprintf(line, sizeof line, "  %-35s v%d, %2zu inputs: %s", name.c_str(), m.version(), m.width(),
                  m.description().c_str());
    print_line(line);
  }
  print_line("each also as NAME/velocity (the regressor answers the cup velocity to set), NAME/position (the cup pose "
             "to servo to), on the arm NAME/torque (its four joint torques) or NAME/osc (a cup pose and the posture's "
             "acceleration that operational-space control turns into held joint torques; NAME with links) and, under delays, NAME/ahead (the cup where the action lands) or NAME/landing (and the "
             "clock of that step), as in NAME/position/landing");
  print_line("a name is parts joined by +, each once and in this order: state or cup, links (the arm's link angles "
             "and rates), clock, start or start_state "
             "(either may end in @dice: x measured from the start's mean die x), history, retry (the clock and the "
             "start restart at each attempt); any such name is a map (docs/learners.md, \"Feature-map names\")");
  return 0;
}

int run_list(const ListOptions& opt) {
  if (opt.markdown) {
    std::cout << regressors_reference_markdown();
    return 0;
  }
  const auto& reg = RegressorRegistry::global();
  if (opt.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& name : reg.names()) {
      const auto& i = reg.info(name);
      nlohmann::json params = nlohmann::json::array();
      for (const auto& p : i.params)
        params.push_back({{"name", p.name}, {"type", to_string(p.type)}, {"default", p.default_value}, {"help", p.help}});
      out.push_back({{"name", name}, {"description", i.description}, {"source", i.source}, {"params", params}});
    }
    print_line(out.dump());
    return 0;
  }
  for (const auto& name : reg.names()) {
    const auto& i = reg.info(name);
    print_line(name + "  (" + i.source + ")\n    " + i.description);
    print_params(i.params, "--set");
  }
  return 0;
}

struct RegressorBenchOptions {
  WorldOption world;
  std::filesystem::path demos, queries, export_dir;
  std::string split = "episodes";
  std::string features = "state";
  std::vector<std::string> regressors;
  std::vector<std::string> sets;
  std::uint64_t seed = 1;
  int calls = 2000;
  bool json = false;
};

// Writes X and Y of one side of the split as CSV with a header (17 significant digits, so
// another tool reads back exactly these doubles).
template <class Names>
void write_matrix_csv(const std::filesystem::path& path, const Matrix& m, const Names& names) {
  std::string header;
  for (std::size_t j = 0; j < names.size(); ++j) header += (j ? "," : "") + std::string(names[j]);
  AtomicFile file(path, Ownership::first_line("dicestack exported split CSV", {header}));
  auto& out = file.stream();
  out.precision(17);
  out << header << '\n';
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) out << m(i, j) << (j + 1 < m.cols() ? ',' : '\n');
  file.commit();
}

void export_split(const Split& split, const FeatureMap& features, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::vector<std::string> columns = features.column_names();
  write_matrix_csv(dir / "train_x.csv", split.train.x, columns);
  const auto answers = features.answer_names();
  write_matrix_csv(dir / "train_y.csv", split.train.y, answers);
  write_matrix_csv(dir / "test_x.csv", split.test.x, columns);
  write_matrix_csv(dir / "test_y.csv", split.test.y, answers);
}

int run_bench(const RegressorBenchOptions& opt) {
  const WorldConfig world = opt.world.load();
  const auto dir = opt.demos.empty() ? human_demo_set(world) : opt.demos;
  const DemoSet set = read_demo_set(dir);
  const DemoSplit demo_split(set.episodes, opt.split);
  const FeatureMap& features = feature_map(opt.features);
  const Split& split = demo_split.matrices(features);
  if (!opt.export_dir.empty()) export_split(split, features, opt.export_dir);
  // predict_row is timed on the test states, or on another set's (e.g. a policy's saved rollouts,
  // which stray from the training states as no test split does).
  std::optional<DemoSplit> query_split;
  if (!opt.queries.empty()) {
    query_split.emplace(read_demo_set(opt.queries).episodes, "none");
    if (query_split->matrices(features).train.x.rows() == 0)
      throw InputError(opt.queries.string() + ": --queries holds no states to time predict_row on");
  }
  const Matrix& queries = query_split     ? query_split->matrices(features).train.x
                          : split.test.rows() > 0 ? split.test.x
                                                  : split.train.x;
  auto& reg = RegressorRegistry::global();
  const auto names = opt.regressors.empty() ? reg.names() : opt.regressors;
  nlohmann::json rows = nlohmann::json::array();
  if (!opt.json) {
    if (query_split) print_line("predict_row timed on the " + std::to_string(queries.rows()) + " states of " + opt.queries.string());
    print_line("bench regressors: " + dir.string() + ", split " + split.description + "; " +
               std::to_string(split.train.rows()) + " training rows, " + std::to_string(split.test.rows()) + " test rows, features " +
               features.name() + " (" + std::to_string(features.width()) + " inputs)");
    print_line("  regressor        fit s   predict_row us   batch rows/s   train error   test error");
  }
  for (const auto& name : names) {
    auto t0 = std::chrono::steady_clock::now();
    Model model = Model::train(reg.create(name, opt.sets), split.train.x, split.train.y, opt.seed, nullptr, features);
    const double fit_s = seconds_since(t0);
    // predict_row: median over batches of 50 calls (a timer read per call would dominate the
    // fastest regressors).
    const Matrix probe = model.x_scaler().apply(queries);
    std::vector<double> per_call;
    double out[kMaxOutputWidth];
    const auto n = static_cast<std::size_t>(probe.rows());
    for (int b = 0; b < std::max(1, opt.calls / 50); ++b) {
      t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < 50; ++k) {
        const auto row = static_cast<Eigen::Index>((static_cast<std::size_t>(b) * 50 + static_cast<std::size_t>(k)) % n);
        model.regressor().predict_row({probe.row(row).data(), static_cast<std::size_t>(probe.cols())}, {out, model.regressor().output_dim()});
      }
      per_call.push_back(seconds_since(t0) / 50.0);
    }
    std::sort(per_call.begin(), per_call.end());
    const double row_us = 1e6 * per_call[per_call.size() / 2];
    t0 = std::chrono::steady_clock::now();
    model.predict(split.train.x);
    const double batch_rate = static_cast<double>(split.train.rows()) / seconds_since(t0);
    const Score errors = score(model, split);
    nlohmann::json row{{"name", name},
                       {"fit_s", fit_s},
                       {"predict_row_us", row_us},
                       {"batch_rows_per_s", batch_rate},
                       {"train_error", errors.train_error},
                       {"split", opt.split},
                       {"train_rows", split.train.rows()},
                       {"timed_rows", queries.rows()},
                       {"features", features.name()}};
    if (errors.test_error) row["test_error"] = *errors.test_error;  // none: the split left no test row
    rows.push_back(row);
    if (!opt.json) {
      char test[32] = "-", line[256];
      if (errors.test_error) std::snprintf(test, sizeof test, "%.3f", *errors.test_error);
      std::snprintf(line, sizeof line, "  %-14s %7.2f %16.2f %14.0f %13.3f %12s", name.c_str(), fit_s, row_us, batch_rate,
                    errors.train_error, test);
      print_line(line);
    }
  }
  if (opt.json) print_line(rows.dump());
  return 0;
}

}  // namespace

void add_regressors_command(CLI::App& app) {
  auto list = std::make_shared<ListOptions>();
  CLI::App* cmd = app.add_subcommand("regressors", "List the registered regressors and their parameters");
  cmd->add_flag("--json", list->json, "Print JSON");
  cmd->add_flag("--markdown", list->markdown, "Print the reference page of the built-in ones (docs/reference/regressors.md)");
  cmd->callback([list] { run_list(*list); });
}

void add_learners_command(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("learners", "List the learners and their options");
  auto markdown = std::make_shared<bool>(false);
  cmd->add_flag("--markdown", *markdown, "Print the reference page (docs/reference/learners.md)");
  cmd->callback([markdown] { run_learners(*markdown); });
}

void add_bench_regressors_command(CLI::App& bench) {
  auto opt = std::make_shared<RegressorBenchOptions>();
  CLI::App* cmd = bench.add_subcommand("regressors", "Fit time, predict_row latency and eq. 9 errors of each regressor");
  opt->world.add_to(*cmd);
  cmd->add_option("--demos", opt->demos, "Demonstration folder (default: the paper's 68 recordings, converted)");
  cmd->add_option("--split", opt->split, "episodes (i % 5 == 4 is test) or rows (the paper's random 25%)")
      ->check(CLI::IsMember({"episodes", "rows"}))
      ->capture_default_str();
  cmd->add_option("--queries", opt->queries,
                  "Time predict_row on this set's states (e.g. a policy's `evaluate --save-rollouts`) instead of the test states");
  cmd->add_option("--features", opt->features, "Feature map the rows go through (`dicestack learners` lists them)")
      ->capture_default_str();
  cmd->add_option("--regressors", opt->regressors, "Only these (comma-separated)")->delimiter(',');
  cmd->add_option("--set", opt->sets, "key=value parameter for the regressor(s); repeatable");
  cmd->add_option("--seed", opt->seed, "Training seed")->check(seed_check())->capture_default_str();
  cmd->add_option("--calls", opt->calls, "predict_row calls timed")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print a JSON list");
  cmd->add_option("--export", opt->export_dir,
                  "Also write the split as train_x.csv, train_y.csv, test_x.csv, test_y.csv to this folder "
                  "(to fit other tools on the same rows: bench/compare_python.py)");
  cmd->callback([opt] { run_bench(*opt); });
}

}  // namespace dicestack::cli
