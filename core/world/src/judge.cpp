#include <dicestack/core/judge.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <dicestack/core/geometry.hpp>
#include <dicestack/core/world.hpp>

namespace dicestack {
namespace {

namespace si = state_index;

// Distance from `angle` to the nearest multiple of 90 degrees.
double off_quarter_turn(double angle) {
  const double q = std::numbers::pi / 2.0;
  return std::abs(angle - q * std::round(angle / q));
}

}  // namespace

int count_dice_in_cup(const State& s, const WorldConfig& config) {
  const double angle = s[si::kCupAngle];
  const CupGeometry cup = cup_geometry(config.cup);
  // Off the table: at least two gap tolerances (8 cm) above a resting die, so the dice falling
  // the 5 cm of the start do not count.
  const double on_table = table_height(config.walls) + config.dice.half_size + 2.0 * config.judge.gap_tolerance;
  const Vec2 com{s[si::kCupX], s[si::kCupY]};
  const double h = config.cup.wall_height, w = config.cup.base_width, f = config.cup.flare;
  int count = 0;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i);
    if (s[d + 1] <= on_table) continue;
    const Vec2 local = to_local(com, angle, {s[d], s[d + 1]});
    // Back to the anchor frame, where the base runs from (0, 0) to (w, 0).
    const double x = local.x + cup.com_from_anchor.x, y = local.y + cup.com_from_anchor.y;
    if (y <= 0.0 || y >= h) continue;
    const double left = -f * y / h, right = w + f * y / h;
    if (x > left && x < right) ++count;
  }
  return count;
}

namespace {

// The dice from the lowest to the highest.
std::array<std::size_t, kDiceCount> dice_bottom_up(const State& s) {
  std::array<std::size_t, kDiceCount> order{0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return s[si::die(a) + 1] < s[si::die(b) + 1]; });
  return order;
}

// The centre height of the k-th die of a stack on the table (0: the bottom one).
double stacked_height(const WorldConfig& config, std::size_t k) {
  return table_height(config.walls) + config.dice.half_size + 2.0 * config.dice.half_size * static_cast<double>(k);
}

}  // namespace

bool is_stacked(const State& s, const WorldConfig& config) {
  const auto& j = config.judge;
  const auto order = dice_bottom_up(s);
  for (std::size_t k = 0; k < kDiceCount; ++k) {
    const std::size_t d = si::die(order[k]);
    const double expected_y = stacked_height(config, k);
    if (std::abs(s[d + 1] - expected_y) > j.gap_tolerance * static_cast<double>(k + 1)) return false;
    if (k > 0 && std::abs(s[d] - s[si::die(order[k - 1])]) > j.column_tolerance) return false;
    if (off_quarter_turn(s[d + 2]) > j.angle_tolerance) return false;
    if (std::hypot(s[d + 3], s[d + 4]) > j.rest_speed) return false;
    if (std::abs(s[d + 5]) > j.rest_angular_speed) return false;
  }
  return true;
}

double stack_shortfall(const State& s, const WorldConfig& config) {
  const auto& j = config.judge;
  const auto order = dice_bottom_up(s);
  double sum = 0.0;
  for (std::size_t k = 0; k < kDiceCount; ++k) {
    const std::size_t d = si::die(order[k]);
    const double expected_y = stacked_height(config, k);
    sum += std::abs(s[d + 1] - expected_y) / (j.gap_tolerance * static_cast<double>(k + 1));
    if (k > 0) sum += std::abs(s[d] - s[si::die(order[k - 1])]) / j.column_tolerance;
    sum += off_quarter_turn(s[d + 2]) / j.angle_tolerance;
    sum += std::hypot(s[d + 3], s[d + 4]) / j.rest_speed + std::abs(s[d + 5]) / j.rest_angular_speed;
  }
  return sum;
}

bool failed_at_rest(const State& s, const WorldConfig& config) {
  const auto& j = config.judge;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i);
    if (std::hypot(s[d + 3], s[d + 4]) > j.rest_speed || std::abs(s[d + 5]) > j.rest_angular_speed) return false;
  }
  // Dice at rest in a cup held still in the air are not down yet; a cup left over a fallen
  // column, or lifted off it, has let them down: the lowest lies on the table.
  const double lowest = s[si::die(dice_bottom_up(s)[0]) + 1];
  return lowest <= table_height(config.walls) + config.dice.half_size + j.gap_tolerance && !is_stacked(s, config);
}

std::size_t attempt_start(std::span<const State> states, const WorldConfig& config, const AttemptRule& rule) {
  if (states.empty() || rule.rest_steps < 1) return 0;
  const auto earliest = static_cast<std::size_t>(std::max(rule.earliest, 0));
  const auto need = static_cast<std::size_t>(rule.rest_steps);
  // Back from the last state: the latest run of failed states long enough to start an attempt.
  // A run that ends by `earliest` cannot, so the scan stops there.
  std::size_t end = states.size();  // one past the run's last state
  while (true) {
    while (end > earliest && !failed_at_rest(states[end - 1], config)) --end;
    if (end <= earliest) return 0;
    std::size_t begin = end;
    while (begin > 0 && failed_at_rest(states[begin - 1], config)) --begin;
    // The run [begin, end) starts an attempt at the first step >= earliest that closes `need`
    // failed states in a row.
    const std::size_t at = std::max(begin + need - 1, earliest);
    if (at < end) return at;
    end = begin;
  }
}

Settled settle(const State& state, const WorldConfig& config, int max_steps) {
  World world(config, state);
  Settled r;
  for (r.steps = 0; r.steps < max_steps; ++r.steps) {
    const State s = world.state();
    if (is_stacked(s, config)) {
      r.stacked = true;
      break;
    }
    r.wall_contact = world.step({-s[si::kCupVx], -s[si::kCupVy], -s[si::kCupW]}) || r.wall_contact;
  }
  return r;
}

void observe(Outcome& o, const State& s, bool wall_contact_step, const WorldConfig& config) {
  ++o.steps;
  o.dice_in_cup_now = count_dice_in_cup(s, config);
  o.dice_in_cup = std::max(o.dice_in_cup, o.dice_in_cup_now);
  o.stacked = is_stacked(s, config);
  o.stacked_steps = o.stacked ? o.stacked_steps + 1 : 0;
  o.wall_contact = o.wall_contact || wall_contact_step;
}

}  // namespace dicestack
