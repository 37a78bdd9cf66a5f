#pragma once
// Paths robust by construction (TrackerConfig::refine): a path's cup pose moved by smooth
// offsets that CMA-ES chooses to succeed from many starts, followed clean and under noise.
#include <cstdint>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack::tracker_detail {

struct RefinedPath {
  CupPath path;      ///< named "NAME (refined)", its actions folded into its velocities
  int original = 0;  ///< successes of the path given, in the validation trials
  int refined = 0;   ///< successes of `path`, in the same trials
  int trials = 0;    ///< validation trials of each: fresh starts, each followed clean and noisy
};

/// Refines `path` for config.refine generations of config.refine_probes starts (training
/// starts drawn from `seed`), then plays both from 4 x refine_probes fresh starts. Deterministic
/// in its arguments, the same on any number of threads or ranks. Collective over `cluster`.
RefinedPath refine_path(const CupPath& path, const WorldConfig& world, const TrackerConfig& config, std::uint64_t seed,
                        int threads, Cluster& cluster);

}  // namespace dicestack::tracker_detail
