#pragma once
// Counts from users, checked against this machine's memory before any work: a run
// that would hold more than it can is refused saying what it would need, not ended by
// std::bad_alloc halfway.
#include <cstdint>
#include <string_view>

namespace dicestack {

/// This machine's physical memory in bytes (0 if unknown).
std::uint64_t physical_memory();

/// Throws ConfigError unless `count` items of up to `bytes_each` bytes fit in half of this
/// machine's memory, e.g. "record: 1000000000 episodes would need up to 85 TB in memory (up to
/// 92 KB each); this machine has 23 GB: at most 126000 fit".
void require_memory(std::string_view what, std::uint64_t count, double bytes_each, std::string_view items);

}  // namespace dicestack
