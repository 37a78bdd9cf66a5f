// The error metrics: eq. 9's scaled L1 error and the labels' column sigma.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/matrix.hpp>
#include <dicestack/datasets/metrics.hpp>

namespace dicestack {
namespace {

TEST(Metrics, ScaledL1ByHand) {
  Matrix y(3, 2), yhat(3, 2);
  y << 1, 2, 3, 4, 5, 6;
  yhat << 1, 3, 1, 4, 5, 2;
  const std::vector<double> sigma{2.0, 4.0};
  // Row errors: 0 + 1/4, 2/2 + 0, 0 + 4/4  -> (0.25 + 1 + 1) / 3
  EXPECT_DOUBLE_EQ(scaled_l1_error(y, yhat, sigma), 2.25 / 3.0);
  EXPECT_THROW(scaled_l1_error(y, Matrix(2, 2), sigma), InputError);
  EXPECT_THROW(scaled_l1_error(y, yhat, std::vector<double>{1.0, 0.0}), InputError);
  const auto cs = column_sigma(y);
  EXPECT_DOUBLE_EQ(cs[0], std::sqrt(8.0 / 3.0));
}

}  // namespace
}  // namespace dicestack
