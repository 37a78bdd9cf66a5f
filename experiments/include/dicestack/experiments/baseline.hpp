#pragma once
// The baselines without demonstrations (paper section VI-B) as a registry: each one is
// optimised or learned from the world alone with a profile's budget, then rolled out like a
// learned policy in its own leaderboard row.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/world_config.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/profile.hpp>

namespace dicestack {

struct BaselineInfo {
  std::string name;
  std::string description;
  double quick_seconds = 30.0;  ///< estimated cost on one core under the quick profile (for dealing rows)
  /// Its budget under a profile (evaluations, updates or nodes); its cost grows in proportion.
  std::function<int(const Profile&)> budget;
  /// Optimises (or learns) from the world's start with the profile's budget and returns the
  /// policy that plays the result: an open-loop action sequence, or REINFORCE's network.
  std::function<PolicyFactory(const WorldConfig& world, const Profile& profile, std::uint64_t seed, int threads)> make;
};

/// Every open-loop optimiser (optimiser_names(): cmaes, de, basinhop, bayes), then reinforce and rrt.
const std::vector<BaselineInfo>& baselines();
/// Throws ConfigError naming the baselines for an unknown name.
const BaselineInfo& baseline(const std::string& name);
std::vector<std::string> baseline_names();

}  // namespace dicestack
