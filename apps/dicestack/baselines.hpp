#pragma once
// What the baseline commands (optimise, reinforce, rrt, bench optimise) share: the open-loop
// problem's options, and writing a baseline's result (its episode as a demonstration set, its
// summary JSON, its line of text).
#include <cstdint>
#include <filesystem>
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

/// Writes one episode as a demonstration set at `out` (ours or new only).
void write_episode_set(const WorldConfig& world, const Episode& e, const std::string& description,
                       const std::string& provenance, const std::filesystem::path& out);

/// A baseline's episode outcome, for its JSON summary and its text line.
nlohmann::json outcome_json(const Outcome& o);
std::string outcome_text(const Outcome& o);

/// Writes `summary` (with `curve` under `curve_key`) to `file` atomically, then prints the
/// summary as JSON or the text. Returns the exit status.
int finish_baseline(const std::filesystem::path& file, nlohmann::json summary, const std::string& curve_key,
                    const nlohmann::json& curve, bool json, const std::string& text);

}  // namespace dicestack::cli
