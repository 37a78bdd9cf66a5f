#pragma once
// What the regressors' suite files share: every registered name with the example plugin loaded,
// and a known function with random inputs to learn it from (include only in
// dicestack_regressors_tests).
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <dicestack/core/matrix.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack::test {

/// Every registered name, after loading the example ridge plugin into the global registry.
inline std::vector<std::string> registered_with_plugin() {
  RegressorRegistry::global().load_plugin(DICESTACK_RIDGE_PLUGIN);
  return RegressorRegistry::global().names();
}

/// A smooth nonlinear map from d inputs to 3 outputs (linear when `linear`).
inline Matrix target(const Matrix& x, bool linear) {
  Matrix y(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const auto r = x.row(i);
    y(i, 0) = 0.8 * r(0) - 0.5 * r(1) + 0.3 * r(5);
    y(i, 1) = linear ? 0.4 * r(2) + 0.2 * r(3) - 0.1 : std::sin(1.5 * r(2)) + 0.3 * r(3) * r(4);
    y(i, 2) = linear ? -0.6 * r(0) + 0.7 * r(7) : std::tanh(r(0) + r(6)) - 0.2 * r(7) * r(7);
  }
  return y;
}

/// An n x d matrix of standard normal values, from `seed`.
inline Matrix inputs(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix x(n, d);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = rng.normal();
  return x;
}

}  // namespace dicestack::test
