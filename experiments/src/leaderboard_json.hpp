#pragma once
// What the leaderboard's run and its formats share: a row as JSON, and the json format's name.
#include <nlohmann/json.hpp>

#include <dicestack/experiments/leaderboard.hpp>

namespace dicestack {

/// The json format's "format".
inline constexpr const char* kLeaderboardFormat = "dicestack-leaderboard";

/// A row as the json format and the progress file write it: names, errors, counts, rates with
/// their 95 % Wilson intervals, timings.
nlohmann::json leaderboard_row_object(const LeaderboardRow& row);

}  // namespace dicestack
