#pragma once
// What the baseline commands (optimise, reinforce, rrt, bench optimise) share: the open-loop
// problem's options, and writing a baseline's result (its episode as a demonstration set, its
// summary JSON, its line of text).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/open_loop.hpp>
#include <dicestack/datasets/episode.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {

struct OptimiseCommandOptions {
  WorldOption world;
  OptimiseOptions optimiser;
  OpenLoopSettings settings;
  double gravity_scale = 1.0, noise = 0.0, discount = -1.0;
  int threads = 0;
  std::filesystem::path out;
  bool json = false;
};

/// The world the options describe: gravity scaled, action noise and discount set.
WorldConfig open_loop_world(const OptimiseCommandOptions& opt);

/// --world, --steps, --gravity-scale, --noise, --repeats, --discount, --threads.
void add_problem_options(CLI::App& cmd, OptimiseCommandOptions& opt);

/// A baseline's action sequence played once from the paper's start through rollout(), as an
/// episode (it ends after the last action, or at a held success).
Episode replay(const WorldConfig& world, const std::vector<Action>& actions, std::uint64_t seed, const std::string& origin);

/// A baseline's episode outcome, for its JSON summary and its text line.
nlohmann::json outcome_json(const Outcome& o);
std::string outcome_text(const Outcome& o);

/// What a baseline command leaves in its --out folder.
struct BaselineOutput {
  std::filesystem::path out;            ///< the folder (--out): ours or new only
  WorldConfig world;                    ///< the world the episode was played in
  std::optional<Episode> episode;       ///< the result as an episode; none (an empty set): RRT found no path
  std::string description, provenance;  ///< for the set's meta.json
  std::string summary_file;             ///< "optimise.json", "reinforce.json" or "rrt.json"
  nlohmann::json summary;               ///< saved with the format marker, and printed by --json
  std::string curve_key;                ///< where `curve` goes in the saved summary (null: none)
  nlohmann::json curve;
};

/// Writes the episode as a demonstration set and the summary beside it in one swap
/// (write_demo_set with a sidecar), so a kill leaves the old folder whole, then prints the
/// summary as JSON or the text. Returns the exit status.
int finish_baseline(const BaselineOutput& output, bool json, const std::string& text);

}  // namespace dicestack::cli
