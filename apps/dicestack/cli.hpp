#pragma once
// The dicestack command line: one file per subcommand, one catch in run() (STYLE 8).
#include <CLI/CLI.hpp>

namespace dicestack::cli {

/// Parses argv, runs the chosen subcommand and returns the process exit status: 0 on success,
/// 1 for a dicestack::Error (message on stderr), CLI11's codes for usage errors.
int run(int argc, char** argv);

// Each subcommand file registers itself on the top-level app.
void add_bench_command(CLI::App& app);
void add_config_command(CLI::App& app);
void add_dataset_commands(CLI::App& app);  // import, dataset
void add_evaluate_command(CLI::App& app);
void add_leaderboard_command(CLI::App& app);
void add_learners_command(CLI::App& app);
void add_play_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_record_command(CLI::App& app);
void add_regressors_command(CLI::App& app);
void add_render_command(CLI::App& app);
void add_rollout_command(CLI::App& app);
void add_bench_regressors_command(CLI::App& bench);  // under `bench`
void add_bench_load_command(CLI::App& bench);        // under `bench`
void add_bench_dataset_command(CLI::App& bench);     // under `bench`
void add_interop_commands(CLI::App& import, CLI::App& dataset);  // import robomimic|minari, dataset export
void add_bench_optimise_command(CLI::App& bench);    // under `bench`
void add_optimise_command(CLI::App& app);
void add_reinforce_command(CLI::App& app);
void add_rrt_command(CLI::App& app);

}  // namespace dicestack::cli
