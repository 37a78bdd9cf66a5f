#pragma once
// Where episodes start and where the optimisers' cost wants them to end.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// The paper's start: the cup hanging mouth-down over three dice lying in a row (DESIGN table).
State paper_start_state(const WorldConfig& config);

/// A start drawn from config.randomization with `seed`: the scene shifted in x, each die
/// jittered and turned by a multiple of 90 degrees, the cup lifted and tilted. Draws again
/// (deterministically) while shapes overlap. Throws ConfigError if no valid start is found.
State random_start_state(const WorldConfig& config, std::uint64_t seed);

/// How far the paper's starts shift the whole scene in x: U(-this, this), m. The paper's code
/// started every episode from one pose; a small shift keeps a hundred episodes from being one.
inline constexpr double kPaperStartShift = 0.02;

/// The start distributions a command names with `--start`: "random" (config.randomization as it
/// is) and "paper" (the paper's start at rest, the whole scene shifted in x by
/// U(-kPaperStartShift, kPaperStartShift); nothing else drawn).
std::vector<std::string> start_names();

/// `config` with the start distribution `starts` (one of start_names()): "paper" replaces its
/// randomization, "random" leaves it. Every start drawn from the result (evaluation, training,
/// recording) comes from that distribution. Throws ConfigError for another name, listing them.
WorldConfig with_starts(WorldConfig config, std::string_view starts);

/// The name of `config`'s start distribution: "paper" when its randomization is the paper's
/// starts', else "random".
std::string start_distribution_name(const WorldConfig& config);

/// Seed of evaluation start `index` of a run seeded with `seed` (`evaluate --seed`, the
/// leaderboard's rollouts): derive_seed(seed, index).
std::uint64_t evaluation_start_seed(std::uint64_t seed, std::uint64_t index);

/// Seed of training start `index`: every start training sees (record, the built-in set, DART,
/// DAgger's rollouts) comes from this stream, apart from evaluation's, so that `record --seed 0`
/// and `evaluate --seed 0` share no start: derive_seed(derive_seed(seed, kTrainingStream), index).
inline constexpr std::uint64_t kTrainingStream = 0x747261696e696e67ULL;  // "training"
std::uint64_t training_start_seed(std::uint64_t seed, std::uint64_t index);

/// The paper's goal: the three dice at rest in one column at cost.goal_x on the table, die 0
/// at the bottom, unrotated; the cup at its start pose and at rest.
State goal_state(const WorldConfig& config);

}  // namespace dicestack
