#include <dicestack/core/initial_state.hpp>

#include <numbers>

#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/world.hpp>

namespace dicestack {

namespace si = state_index;

State paper_start_state(const WorldConfig& config) {
  const CupGeometry cup = cup_geometry(config.cup);
  State s{};
  // At angle 0 the centre of mass sits at anchor + com; the start rotates about that point.
  s[si::kCupX] = config.cup.start_anchor.x + cup.com_from_anchor.x;
  s[si::kCupY] = config.cup.start_anchor.y + cup.com_from_anchor.y;
  s[si::kCupAngle] = config.cup.start_angle;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    s[si::die(i)] = config.dice.start_x[i];
    s[si::die(i) + 1] = config.dice.start_y;
  }
  return s;
}

std::vector<std::string> start_names() { return {"random", "paper"}; }

WorldConfig with_starts(WorldConfig config, std::string_view starts) {
  if (starts == "paper") {
    config.randomization = RandomizationConfig{kPaperStartShift, 0.0, 0.0, 0.0, false};
  } else if (starts != "random") {
    throw ConfigError("unknown start distribution \"" + std::string(starts) + "\"; expected random or paper");
  }
  return config;
}

std::string start_distribution_name(const WorldConfig& config) {
  return config.randomization == with_starts(config, "paper").randomization ? "paper" : "random";
}

std::uint64_t evaluation_start_seed(std::uint64_t seed, std::uint64_t index) { return derive_seed(seed, index); }

std::uint64_t training_start_seed(std::uint64_t seed, std::uint64_t index) {
  return derive_seed(derive_seed(seed, kTrainingStream), index);
}

State random_start_state(const WorldConfig& config, std::uint64_t seed) {
  const auto& r = config.randomization;
  Rng rng(seed);
  World probe(config);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    State s = paper_start_state(config);
    const double shift = rng.uniform(-r.shift, r.shift);
    s[si::kCupX] += shift;
    s[si::kCupY] += rng.uniform(0.0, r.cup_lift);
    s[si::kCupAngle] += rng.uniform(-r.cup_tilt, r.cup_tilt);
    for (std::size_t i = 0; i < kDiceCount; ++i) {
      s[si::die(i)] += shift + rng.uniform(-r.die_jitter, r.die_jitter);
      const auto turns = r.die_quarter_turns ? rng.below(4) : 0;
      s[si::die(i) + 2] = static_cast<double>(turns) * std::numbers::pi / 2.0;
    }
    probe.set_state(s);
    if (!probe.has_overlaps()) return s;
  }
  throw ConfigError(
      "world config: no start without overlapping shapes in 1000 draws: the cup (cup.start_anchor, cup.start_angle) "
      "overlaps the dice (dice.start_x, dice.start_y) or the walls at most draws of randomization.shift, cup_lift and "
      "cup_tilt");
}

State goal_state(const WorldConfig& config) {
  State s = paper_start_state(config);
  const double bottom = table_height(config.walls) + config.dice.half_size;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    s[si::die(i)] = config.cost.goal_x;
    s[si::die(i) + 1] = bottom + 2.0 * config.dice.half_size * static_cast<double>(i);
    s[si::die(i) + 2] = 0.0;
  }
  return s;
}

}  // namespace dicestack
