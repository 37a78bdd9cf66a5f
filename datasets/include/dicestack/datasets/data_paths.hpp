#pragma once
// Where shipped data and generated demonstration sets live, so that commands work on a fresh
// clone without a manual step.
#include <filesystem>

#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// The shipped data folder (holds cupdice/): $DICESTACK_DATA_DIR if set, else the source
/// tree's data/ when run from a build tree, else <install prefix>/share/dicestack.
/// Throws InputError if none exists.
std::filesystem::path data_dir();

/// Cache for generated sets: $DICESTACK_CACHE_DIR, else $XDG_CACHE_HOME/dicestack, else
/// ~/.cache/dicestack (created on demand).
std::filesystem::path cache_dir();

/// The paper's 68 recordings converted for `world`; imported into the cache on first use
/// (folder human-v2-<world hash>: v2 since the sets carry format v2's transitions), then read
/// from there.
std::filesystem::path human_demo_set(const WorldConfig& world);

}  // namespace dicestack
