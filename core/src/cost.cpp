#include <dicestack/core/cost.hpp>

#include <cmath>
#include <numbers>

namespace dicestack {

double state_distance(const State& a, const State& b, const CostConfig& cost) {
  double sum = 0.0;
  for (std::size_t j = 3; j < kStateDim; ++j) {
    double diff = a[j] - b[j];
    const bool die_angle = j < 21 && (j - 3) % 6 == 2;
    if (die_angle) {
      const double q = std::numbers::pi / 2.0;
      diff -= q * std::round(diff / q);
    }
    diff /= cost.sigma[j];
    sum += diff * diff;
  }
  return std::sqrt(sum);
}

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
