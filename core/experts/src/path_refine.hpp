#pragma once
// Paths robust by construction (TrackerConfig::refine): a path's cup pose moved by smooth
// offsets that CMA-ES chooses to succeed from many starts, followed clean and under noise.
#include <cstdint>
#include <functional>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack::tracker_detail {

/// Refines `path` for config.refine generations of config.refine_probes training starts each
/// (drawn from `seed`, as is the search): the returned path is named "NAME (refined)", its actions
/// folded into its velocities. Deterministic in its arguments, the same on any number of threads
/// or ranks. Collective over `cluster`.
/// `generation_done(g, config.refine)` is called after each generation g (may be empty).
CupPath refine_path(const CupPath& path, const WorldConfig& world, const TrackerConfig& config, std::uint64_t seed,
                    int threads, Cluster& cluster, const std::function<void(int, int)>& generation_done = {});

/// Each path's successes from 4 x config.refine_probes validation starts drawn from `seed` (a
/// stream of their own, apart from every refinement's), each followed clean and under
/// refine_noise: the same trials for every path, so their counts compare. Collective.
std::vector<int> validation_successes(const std::vector<CupPath>& paths, const WorldConfig& world, const TrackerConfig& config,
                                      std::uint64_t seed, int threads, Cluster& cluster);

/// The trials validation_successes counts per path.
inline int validation_trials(const TrackerConfig& config) { return 8 * config.refine_probes; }

}  // namespace dicestack::tracker_detail
