#pragma once
// An Episode as compact bytes, for episodes that travel between the ranks of a Cluster
// (evaluation rollouts, recorded demonstrations, DAgger's aggregate). Every field, doubles bit
// for bit; the same build on the same kind of machine reads it back (no versioning: these bytes
// never reach a file).
#include <string>
#include <string_view>

#include <dicestack/core/cluster.hpp>
#include <dicestack/datasets/episode.hpp>

namespace dicestack {

/// Appends `e` to `out`.
void pack_episode(Packer& out, const Episode& e);
/// Reads an episode pack_episode wrote; throws Error when the bytes run out.
Episode unpack_episode(Unpacker& in);

/// One episode alone as bytes, and back.
std::string episode_to_bytes(const Episode& e);
Episode episode_from_bytes(std::string_view bytes);

}  // namespace dicestack
