#pragma once
// The robustness table (issue 25): a policy's realistic success in perturbed worlds, factor by
// factor and level by level, with Wilson intervals (docs/robustness.md).
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
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
  /// Called as each row starts with (row index, rows in all, factor, level).
  std::function<void(int, int, const std::string&, const std::string&)> progress;
};

/// The rows: nominal, then every factor at easy, medium and hard, then all factors at once at
/// each level. Each row is an evaluation (collective over `cluster`; the same rows on any number
/// of threads or ranks).
std::vector<RobustnessRow> robustness(const PolicyFactory& make_policy, const WorldConfig& world,
                                      const RobustnessRequest& request, Cluster& cluster = local_cluster());

/// The table as "md", "csv" or "json" (the leaderboard's formats; `header` heads md and is
/// "header" in json). Throws ConfigError for another format.
std::string render_robustness(const std::vector<RobustnessRow>& rows, const std::string& format, const std::string& header);

/// Throws unless `out` may be written in `format` (nothing there, or a robustness table of ours):
/// call it before the rows run.
void check_robustness_out(const std::filesystem::path& out, const std::string& format);
/// Writes the table to `out` atomically, replacing only a table of ours.
void write_robustness(const std::vector<RobustnessRow>& rows, const std::string& format, const std::string& header,
                      const std::filesystem::path& out);

}  // namespace dicestack
