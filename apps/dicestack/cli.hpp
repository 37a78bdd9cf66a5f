#pragma once
// The dicestack command line: one file per subcommand, one catch in run() (STYLE 8).
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include <dicestack/core/cluster.hpp>

namespace dicestack::cli {

/// What becomes of an error: `message` ("dicestack: error: ...") and the exit status `code`.
/// The default prints the message on stderr and returns the code; under MPI, main() prints it
/// once and ends every rank (docs/scaling.md).
using FailFn = std::function<int(const std::string& message, int code)>;

/// Parses argv, runs the chosen subcommand and returns the process exit status: 0 on success,
/// 1 for a dicestack::Error (message on stderr), CLI11's codes for usage errors.
/// With several ranks in `cluster`, evaluate, record, train, leaderboard and optimise (CMA-ES)
/// share their work among them; every other subcommand runs on the root alone while the others wait.
int run(int argc, char** argv, Cluster& cluster = local_cluster(), const FailFn& fail = {});

// Each subcommand file registers itself on the top-level app.
void add_bench_command(CLI::App& app);
void add_config_command(CLI::App& app);
void add_dataset_commands(CLI::App& app);  // import, dataset
void add_evaluate_command(CLI::App& app, Cluster& cluster);
void add_leaderboard_command(CLI::App& app, Cluster& cluster);
void add_learners_command(CLI::App& app);
void add_play_command(CLI::App& app);
void add_train_command(CLI::App& app, Cluster& cluster);
void add_record_command(CLI::App& app, Cluster& cluster);
void add_reference_command(CLI::App& app);  // its cli page reads the whole app as it runs
void add_regressors_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_rollout_command(CLI::App& app);
void add_robustness_command(CLI::App& app, Cluster& cluster);
void add_bench_regressors_command(CLI::App& bench);  // under `bench`
void add_bench_load_command(CLI::App& bench);        // under `bench`
void add_bench_dataset_command(CLI::App& bench);     // under `bench`
void add_interop_commands(CLI::App& import, CLI::App& dataset);  // import robomimic|minari, dataset export
void add_bench_optimise_command(CLI::App& bench);    // under `bench`
void add_bench_estimator_command(CLI::App& bench);   // under `bench`
void add_bench_arm_command(CLI::App& bench);         // under `bench`
void add_bench_arm_open_loop_command(CLI::App& bench);  // under `bench`
void add_optimise_command(CLI::App& app, Cluster& cluster);
void add_reinforce_command(CLI::App& app, Cluster& cluster);
void add_rrt_command(CLI::App& app, Cluster& cluster);

}  // namespace dicestack::cli
