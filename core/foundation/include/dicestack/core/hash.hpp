#pragma once
// FNV-1a fingerprints: of runs (a chain of state hashes), payloads, configs and file headers.
// Not cryptographic: they catch accidents (a damaged file, a changed config), not attacks.
#include <cstdint>
#include <string_view>

#include <dicestack/core/types.hpp>

namespace dicestack {

/// FNV-1a over `bytes`, chained from `seed`: fingerprints of runs, payloads and configs.
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t seed = 0xcbf29ce484222325ULL);

/// FNV-1a over the bytes of `state`, chained from `seed`: a bit-exact fingerprint of a run.
std::uint64_t hash_state(const State& state, std::uint64_t seed = 0xcbf29ce484222325ULL);

}  // namespace dicestack
