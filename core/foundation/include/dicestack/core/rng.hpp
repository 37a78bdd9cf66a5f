#pragma once
// Seeded randomness with results that do not depend on the standard library's distributions
// (std::normal_distribution differs between implementations; ours must not).
#include <array>
#include <cstdint>

namespace dicestack {

/// A stream seed for item `index` of a run seeded with `base` (SplitMix64 of both), so that
/// parallel work draws the same numbers whatever the thread count (STYLE 15).
std::uint64_t derive_seed(std::uint64_t base, std::uint64_t index);

/// A small, fast, copyable generator (xoshiro256**) seeded through SplitMix64.
class Rng {
 public:
  explicit Rng(std::uint64_t seed);
  /// Next 64 random bits.
  std::uint64_t next();
  /// Uniform in [0, 1), 53 bits.
  double uniform();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi);
  /// Uniform integer in [0, n), n > 0.
  std::uint64_t below(std::uint64_t n);
  /// Standard normal (Box–Muller, no cached second value so the state is just four words).
  double normal();

  /// The generator's four state words, to serialise it (environment snapshots).
  std::array<std::uint64_t, 4> words() const { return {s_[0], s_[1], s_[2], s_[3]}; }
  /// A generator continuing from words() exactly. Throws InputError for all-zero words (a
  /// state xoshiro256** never reaches).
  static Rng from_words(const std::array<std::uint64_t, 4>& words);

 private:
  std::uint64_t s_[4];
};

}  // namespace dicestack
