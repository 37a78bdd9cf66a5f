#pragma once
// The paper's RRT variant (Section V-D): grow a tree of reachable world states from the paper's
// start; each extension picks the node nearest a sampled state and optimises a few steps of
// actions (CMA-ES by default; any method of action_sequence.hpp) to move towards it. Nodes keep exact snapshots, so an extension continues
// the very world its node reached (the original's reset to a bare state did not).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>

namespace dicestack {

struct RrtOptions {
  int nodes = 300;             ///< extensions (tree size without the root)
  int extend_steps = 5;        ///< control steps optimised per extension
  int extend_iterations = 5;   ///< generations per extension (basinhop, bayes: that many x population evaluations)
  std::string method = "cmaes";  ///< the extension's optimiser: minimiser_names()
  double goal_bias = 0.1;      ///< probability of sampling the goal state instead of a random one
  int max_depth_steps = 400;   ///< a node this many steps from the root is not extended
  std::uint64_t seed = 0;
  int threads = 0;             ///< an extension's CMA-ES generation is evaluated in parallel
  /// The ranks that share each CMA-ES generation (docs/scaling.md); the same tree on every rank.
  /// The other methods evaluate one point at a time: every rank then repeats the whole search.
  Cluster* cluster = &local_cluster();
};

struct RrtResult {
  std::vector<Action> actions;  ///< from the root to the node nearest the goal
  double best_distance = 0.0;   ///< eq. 6's d(s, goal) at that node
  int nodes = 0;
  long long simulated_steps = 0;
  double seconds = 0.0;
};

/// Deterministic for a seed whatever the thread count. Throws ConfigError for bad options.
RrtResult rrt(const WorldConfig& world, const RrtOptions& options, const std::function<void(int, double)>& progress = {});

}  // namespace dicestack
