#pragma once
// Options shared by several subcommands.
#include <chrono>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack::cli {

/// `--world FILE`: a WorldConfig JSON (`dicestack config` writes the defaults); for commands
/// that draw many starts, also `--start random|paper` (initial_state.hpp's start distributions).
struct WorldOption {
  std::filesystem::path path;
  std::string start = "random";
  std::string embodiment;  ///< `--embodiment`: empty for the file's (the floating cup by default)
  /// `starts`: also bind `--start`.
  void add_to(CLI::App& app, bool starts = false);
  /// The config from the file, or the defaults when no file was given, with `--start`'s
  /// distribution and `--embodiment` when given (checked: an arm must reach the cup's start).
  WorldConfig load() const;
};

/// `--tracker-preset NAME` and `--tracker NAME=VALUE` (repeatable): the tracker expert's settings,
/// by the names the learners' tracker_* options and the bench use (tracker_preset, tracker_config).
struct TrackerOption {
  std::string preset = "plain";
  std::vector<std::string> settings;
  void add_to(CLI::App& app);
  /// Whether any was given (for an expert that is not the tracker, an error).
  bool given() const { return preset != "plain" || !settings.empty(); }
  /// The preset with the settings on top; throws ConfigError naming a bad one.
  TrackerConfig config() const { return tracker_config(preset, settings); }
  /// config() for an expert answering `controller`'s actions: its paths chosen in that
  /// controller and, in joint torques, settled as a learner's is (settle_for_joint_torques): not
  /// refined unless `refine=` is given, ranked from at least 32 probe starts unless `probes=` is.
  TrackerConfig config_for(ActionKind controller) const;
  /// " --tracker-preset P --tracker K=V ..." as given, for a set's provenance.
  std::string as_arguments() const;
};

/// `--seed`: a whole number in [0, 2^64 - 1], written in digits without leading zeros (CLI11
/// alone reads -1 and 2^64 as 2^64 - 1, and "010" as octal).
CLI::Validator seed_check();

/// `--threads`: a whole number in [0, kMaxThreads] (0: all cores).
CLI::Validator threads_check();

/// `--estimator NAME` (none, kalman, particle[:N]): what a policy is shown under sensing factors and delays.
/// Left empty when not given: each model's own (estimator_for), none for an expert.
CLI::Option* add_estimator_option(CLI::App& cmd, std::string& name);

/// `--controller cup|joint_torque` for a command that runs an expert: what it answers on the arm
/// (default cup). Returns the option, so a command can say more in its description.
CLI::Option* add_expert_controller_option(CLI::App& cmd, std::string& name);
/// `--controller cup|joint_torque` with `help` (default: what `name` holds), and the kind a name
/// checked by it stands for.
CLI::Option* add_controller_option(CLI::App& cmd, std::string& name, const std::string& help);
ActionKind controller_kind(const std::string& name);

/// The median of `v` (the benchmarks' figure over repeated runs); 0 for none.
double median(std::vector<double> v);

/// Prints a JSON object or a human-readable text on stdout.
void print_line(const std::string& text);

/// Prints progress on stderr (overwriting the line when stderr is a terminal).
void print_progress(const std::string& text);

/// Seconds since `t0` on the steady clock (the benchmarks' timings).
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// A progress bar on stderr: [#####-----] 50% text, elapsed and estimated time left. On a
/// terminal it redraws one line; otherwise it prints at most one line per `quiet_seconds`.
class ProgressBar {
 public:
  explicit ProgressBar(double quiet_seconds = 10.0);
  /// `fraction` of the whole job done, in [0, 1]. The time left is estimated from the first
  /// update with a fraction above 0 on: work shown at 0 % before it (the tracker preparing its
  /// paths) has no known share of the job.
  void update(double fraction, const std::string& text);
  /// Ends the bar's line on a terminal.
  void finish();

 private:
  std::chrono::steady_clock::time_point start_, last_print_, counted_from_;
  double quiet_, counted_fraction_ = -1.0;  // -1: no fraction above 0 yet
  bool printed_ = false;
};

/// `--demos DIR`: a demonstration folder; without it, the built-in set.
struct DemosOption {
  std::filesystem::path path;
  void add_to(CLI::App& app);
  /// The folder to read (the built-in set is prepared on first use).
  std::filesystem::path resolve(const WorldConfig& world) const;
  /// The same, resolved by the root alone (which makes the built-in set, once) and given to every
  /// rank: every rank must see that path (docs/scaling.md). Collective.
  std::filesystem::path resolve(const WorldConfig& world, Cluster& cluster) const;
};

}  // namespace dicestack::cli
