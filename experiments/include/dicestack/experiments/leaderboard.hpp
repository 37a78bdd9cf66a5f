#pragma once
// The leaderboard: the paper's Table I regenerated. Every regressor under every learner (and
// feature map), with train and test error (eq. 9), rollout outcomes with 95% Wilson intervals,
// fit time and time per step; baselines without demonstrations as rows of their own, and the
// demonstrations' playback for reference. Shared by `dicestack leaderboard` and the Python
// package's dicestack.leaderboard(), which print and write the same tables.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/cluster.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/profile.hpp>

namespace dicestack {

/// What `dicestack leaderboard` asks for; the defaults are the command line's.
struct LeaderboardRequest {
  WorldConfig world;
  std::filesystem::path demos;          ///< the demonstration folder (see resolve_demo_set)
  std::vector<std::string> regressors;  ///< registry names; empty: every registered regressor
  std::vector<std::string> learners;    ///< empty: bc, dagger, dart
  std::vector<std::string> options;     ///< "key=value", applied to every learner that has the key
  /// cmaes, de, basinhop, bayes, reinforce, rrt, or the one name "all": rows without demonstrations.
  std::vector<std::string> baselines;
  /// Feature maps: a row per learner and map it can read; empty: each learner's own (the paper
  /// profile adds "state" and dart's map for every learner that reads them).
  std::vector<std::string> features;
  std::string profile = "quick";  ///< leaderboard_profile(): learner options, budgets, rollouts
  std::string split = "episodes";  ///< "episodes" (i % 5 == 4 is test) or "rows" (the paper's 25 % of rows)
  int episodes = 0;               ///< rollouts per row and training seed; 0: 20 (quick) or 100 (paper)
  int seeds = 1;                  ///< training seeds per row, >= 1
  std::uint64_t seed = 0;         ///< the first training seed, and the seed of the rollouts' starts
  int threads = 0;                ///< 0 = all cores; results do not depend on it
  /// The rollouts' worlds: "none" (the nominal world: today's table byte for byte),
  /// a level or a perturbation file; training stays nominal (learners take perturb= for that).
  std::string perturb = "none";
  /// What the rollouts' policies are shown under sensing factors and delays: "none" (the
  /// observations), an estimator's name (estimator.hpp), or empty: each model's own
  /// (estimator_for; none for a baseline).
  std::string estimator;
  /// What the rows' policies answer: the cup's actions, or joint torques on an arm world (each
  /// learner's own map in torques, torque_map_name; learned by dart and dagger from their
  /// experts, by bc from a set recorded on the arm in torques; no train or test error, as the
  /// recordings hold another controller's actions or none to score). Default learners then:
  /// dart:expert=tracker. No baselines (they act in the cup's actions) and no row split.
  ActionKind controller = ActionKind::cup;
  /// Where the table will be written (empty: nowhere): it and <out>.partial.json are checked
  /// before any work (a user's file is refused), and finished rows go to <out>.partial.json as
  /// they come, so that a rerun with the same settings resumes.
  std::filesystem::path out;
  /// The table's format at `out`: a name of leaderboard_formats() (md, csv, latex, json, html).
  /// html also keeps one successful and one failed rollout of each row for its previews.
  std::string format = "md";
  /// The ranks that share the run (docs/scaling.md). Every rank calls run_leaderboard
  /// with the same request; each training seed of a row (and each baseline) is trained and
  /// rolled out whole on one rank (dealt by estimated_row_cost, longest first), the root writes
  /// <out>.partial.json as rows complete, and every rank returns the same table, identical to a
  /// single process's but for the timings.
  Cluster* cluster = &local_cluster();
};

/// A row's estimated cost in seconds on one core (learner "baseline" for a baseline row, with
/// its name as `regressor`), from measured leaderboards: how rows are dealt among ranks. Only
/// the ratios matter. `rollouts`: the evaluation rollouts of the work dealt (one training seed of
/// a learner row; all seeds of a baseline).
double estimated_row_cost(const std::string& learner, const std::string& regressor, const std::string& features,
                          const Profile& profile, int rollouts);

/// A rollout of a row: its results and the training seed whose model (or baseline) ran it.
struct RowRollout {
  std::uint64_t training_seed = 0;
  EpisodeResult result;
};

/// A rollout kept whole for a results page's looping preview.
struct RowPreview {
  std::uint64_t training_seed = 0;
  int index = 0;              ///< its place among that seed's rollouts
  std::uint64_t seed = 0;     ///< its start's seed
  std::vector<State> states;  ///< the state before each action, then the final state
};

/// One row of the table. Negative errors and times mean "none" (printed "-").
struct LeaderboardRow {
  std::string regressor, learner, features = "-";
  double train_error = 0, test_error = 0, fit_s = 0, us_per_step = 0, dice_in_cup = 0;
  int episodes = 0, stacked = 0, walls = 0, success = 0;
  /// Every rollout, training seeds in order and each seed's in index order (empty for the
  /// demonstrations' playback, and for rows resumed from a progress file that lacks them).
  std::vector<RowRollout> rollouts{};
  /// The first successful and the first failed rollout, when the run kept them (format html).
  std::vector<RowPreview> success_preview{}, failure_preview{};  ///< none or one each
};

/// A finished run: its rows, and the text and settings every format carries.
struct Leaderboard {
  std::vector<LeaderboardRow> rows;
  std::string header;     ///< one line: demonstrations, split, profile, rollouts, options
  std::string meta_json;  ///< the settings as a JSON object (a json table's top-level keys)
  WorldConfig world;      ///< the world the rows ran in (previews are drawn in it)
  std::string demos_description;  ///< the demonstration set's own description (shown on the html page)
};

/// A format a leaderboard can be written in: one entry here is all a new format needs.
struct LeaderboardFormat {
  std::string name;         ///< --format's value
  std::string suffix;       ///< the file suffix that means it (Python's out= picks by it)
  std::string description;  ///< for --help
  /// The text: what `dicestack leaderboard --format NAME` prints (`out` empty), or what goes
  /// to the file `out` (after `marker`), which may refer to files beside it.
  std::function<std::string(const Leaderboard&, const std::filesystem::path& out)> render;
  /// Which existing files at --out it may replace.
  std::function<Ownership()> ownership;
  /// The first line of a written file (a marker comment), or empty.
  std::string marker;
  /// Writes the file `out` and what goes beside it as one unit (the html page and its media
  /// folder); empty: `marker` and render()'s text are written to `out`.
  std::function<void(const Leaderboard&, const std::filesystem::path& out)> write{};
  /// Files beside --out that it writes, checked before any work (empty: none).
  std::function<void(const std::filesystem::path& out)> check_beside{};
  /// The format the command line prints after writing the file (empty: this one).
  std::string echo{};
};

/// Every format, in the order --help lists them.
const std::vector<LeaderboardFormat>& leaderboard_formats();

/// The format named `name`; throws ConfigError listing the names for another.
const LeaderboardFormat& leaderboard_format(const std::string& name);

/// Where a run stands.
struct LeaderboardProgress {
  std::string text;       ///< "[2/6] bc knn: training (seed 0), iteration 1/1, fit"
  double fraction = 0.0;  ///< of the whole run, in [0, 1]
  /// A new step: the command line prints a line for each; the calls in between (each rollout,
  /// each learner report) only tick. Ticks may come from worker threads, several at once.
  bool milestone = false;
};
using LeaderboardProgressFn = std::function<void(const LeaderboardProgress&)>;

/// Trains and rolls out every row. Names (regressors, learners, maps, baselines), the profile,
/// split, format and counts are checked before any work (ConfigError), and so are `out` and its
/// partial file (InputError). Rows already in <out>.partial.json with the same settings are
/// reused. An exception from `progress` ends the run and is rethrown.
Leaderboard run_leaderboard(const LeaderboardRequest& request, const LeaderboardProgressFn& progress = {});

/// The table as text: "md" (the header line, then a Markdown table), "csv", "latex", "json"
/// (the settings and a "rows" array) or "html" (results_page.hpp); what `dicestack leaderboard
/// --format F` prints. Throws ConfigError for another format.
std::string render_leaderboard(const Leaderboard& board, const std::string& format);

/// One row as a JSON object: the json table's row (regressor, learner, features, train_error,
/// test_error, dice_in_cup_mean, episodes, stacked, wall_contact, realistic_success, the three
/// rates with their *_ci95 intervals, fit_s, us_per_step).
std::string leaderboard_row_json(const LeaderboardRow& row);

/// Writes the rendered table to `out` atomically (md, latex and html after a marker line, so
/// that a later run recognises the file as its own), never over a file that is not a dicestack
/// leaderboard of that format, then removes <out>.partial.json. html first writes its media
/// folder beside the page (results_page.hpp). Throws InputError.
void write_leaderboard(const Leaderboard& board, const std::string& format, const std::filesystem::path& out);

}  // namespace dicestack
