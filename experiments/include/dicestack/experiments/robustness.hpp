#pragma once
// The robustness table: a policy's realistic success in perturbed worlds, factor by
// factor and level by level, with Wilson intervals (docs/robustness.md).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/cluster.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/learners/evaluate.hpp>

namespace dicestack {

/// One row: a factor ("none" for the nominal world, "all" for every factor at once) at a level.
struct RobustnessRow {
  std::string factor, level;
  EvalStats stats;
};

struct RobustnessRequest {
  int episodes = 100;      ///< per row
  std::uint64_t seed = 0;  ///< every row's starts: evaluation_start_seed(seed, i)
  int threads = 0;
  /// Leave out the sensing factors (observation noise and delay): an expert reads the world
  /// itself, not the observations, so they would measure nothing.
  bool reads_world = false;
  /// The factors to measure ("none", "all" and perturbation_factors()), in the table's order;
  /// empty: every one. An unknown name is refused before any row runs.
  std::vector<std::string> factors;
  /// What the policy is shown under the sensing factors: the observation, or an estimate.
  EstimatorConfig estimator;
  /// What the policy answers (EvalRequest::actions): its delay, noise and bias are of that kind.
  ActionKind actions = ActionKind::cup;
  /// Called as each row starts with (row index, rows in all, factor, level).
  std::function<void(int, int, const std::string&, const std::string&)> progress;
};

/// Throws ConfigError naming a factor that is none of "none", "all" and perturbation_factors().
void check_robustness_factors(const std::vector<std::string>& factors);

/// The rows: nominal, then every factor at easy, medium and hard, then all factors at once at
/// each level. Each row is an evaluation (collective over `cluster`; the same rows on any number
/// of threads or ranks).
std::vector<RobustnessRow> robustness(const PolicyFactory& make_policy, const WorldConfig& world,
                                      const RobustnessRequest& request, Cluster& cluster = local_cluster());

/// What a table says about its run: its header line and the settings every format carries.
struct RobustnessRun {
  /// What ran, as the header names it: "model m.dsm (knn, state)" or "expert mpc". Shown as
  /// text on the html page, never as markup.
  std::string policy;
  std::string world = "default";  ///< where the world came from: the --world file, or "default"
  int episodes = 0;               ///< rollouts per row
  std::uint64_t seed = 0;         ///< the request's seed
  bool reads_world = false;       ///< an expert: the sensing factors were left out
  std::string estimator = "none";  ///< between the sensors and the policy (none: the observations)
  /// The model's training record (Model::record: learner, demos, ...), shown among the facts.
  std::map<std::string, std::string> record{};
};

/// A finished table: its rows, its header line and its settings.
struct RobustnessTable {
  std::vector<RobustnessRow> rows;
  std::string header;     ///< "dicestack robustness: <policy>; N rollouts per row ... (seed S); ..."
  /// The settings as a JSON object: policy, world, rollouts_per_row, seed, dicestack_version,
  /// sensing_factors (experts only) and model_record (models only). The json format's
  /// top-level keys and the html page's facts.
  std::string meta_json;
};

/// The table of `rows` measured as `run` says: its header line and settings.
RobustnessTable robustness_table(std::vector<RobustnessRow> rows, const RobustnessRun& run);

/// A format the table can be written in: one entry here is all a new format needs (as
/// LeaderboardFormat). None writes files beside the table.
struct RobustnessFormat {
  std::string name;         ///< --format's value
  std::string suffix;       ///< the file suffix that means it
  std::string description;  ///< for --help
  /// The whole text (md and html with their marker line): what is printed, and what goes to --out.
  std::function<std::string(const RobustnessTable&)> render;
  /// Which existing files at --out it may replace.
  std::function<Ownership()> ownership;
  /// The format the command line prints after writing the file (empty: this one).
  std::string echo{};
};

/// Every format, in the order --help lists them: md, csv, json, html. html is a self-contained
/// results page (results_page.hpp's marker; docs/results-pages.md): the table sortable by any
/// column, rates with their 95% Wilson intervals, the settings as facts, no network, no files
/// beside it.
const std::vector<RobustnessFormat>& robustness_formats();

/// The format named `name`; throws ConfigError listing the names for another.
const RobustnessFormat& robustness_format(const std::string& name);

/// The table as text in `format`, a name of robustness_formats(): md (the header line, then a
/// Markdown table), csv, json (the settings, "header" and "rows") or html (a page). Throws
/// ConfigError for another format.
std::string render_robustness(const RobustnessTable& table, const std::string& format);

/// Throws unless `out` may be written in `format` (nothing there, or a table of ours in that
/// format; for html, a dicestack page): call it before the rows run.
void check_robustness_out(const std::filesystem::path& out, const std::string& format);
/// Writes the table to `out` atomically, replacing only a table of ours.
void write_robustness(const RobustnessTable& table, const std::string& format, const std::filesystem::path& out);

}  // namespace dicestack
