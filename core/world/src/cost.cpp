#include <dicestack/core/cost.hpp>

#include <cmath>
#include <numbers>

namespace dicestack {

namespace {

double scaled_sq(const State& a, const State& b, const CostConfig& cost, std::size_t first, std::size_t end = kStateDim) {
  double sum = 0.0;
  for (std::size_t j = first; j < end; ++j) {
    double diff = a[j] - b[j];
    const bool die_angle = j < 21 && (j - 3) % 6 == 2;
    if (die_angle) {
      const double q = std::numbers::pi / 2.0;
      diff -= q * std::round(diff / q);
    }
    diff /= cost.sigma[j];
    sum += diff * diff;
  }
  return sum;
}

}  // namespace

double state_distance(const State& a, const State& b, const CostConfig& cost) { return std::sqrt(scaled_sq(a, b, cost, 3)); }

double tracking_distance_sq(const State& a, const State& b, const CostConfig& cost) { return scaled_sq(a, b, cost, 0); }

double cup_distance_sq(const State& a, const State& b, const CostConfig& cost) { return scaled_sq(a, b, cost, 0, 3); }

double discounted_cost(std::span<const State> trajectory, const State& goal, const CostConfig& cost) {
  // Summed from the end so the weight is a running product, not a power per step.
  double total = 0.0, weight = 1.0;
  for (std::size_t k = trajectory.size(); k-- > 0;) {
    total += weight * state_distance(trajectory[k], goal, cost);
    weight *= cost.gamma;
  }
  return total;
}

}  // namespace dicestack
