#include <dicestack/core/hash.hpp>

namespace dicestack {

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t seed) {
  for (unsigned char c : bytes) seed = (seed ^ c) * 0x100000001b3ULL;
  return seed;
}

std::uint64_t hash_state(const State& state, std::uint64_t seed) {
  return fnv1a({reinterpret_cast<const char*>(state.data()), sizeof(State)}, seed);
}

}  // namespace dicestack
