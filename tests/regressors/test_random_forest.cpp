#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>

#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

Matrix noisy_sine(Eigen::Index n, Matrix* y, std::uint64_t seed) {
  Rng rng(seed);
  Matrix x(n, 4);
  *y = Matrix(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < 4; ++j) x(i, j) = rng.uniform(-2.0, 2.0);
    (*y)(i, 0) = std::sin(x(i, 0)) + 0.1 * rng.normal();
    (*y)(i, 1) = x(i, 1) * x(i, 2);
  }
  return x;
}

TEST(RandomForest, OneSplitSeparatesAStepBetweenDistinctValues) {
  // Labels step from 0 to 1 between x = 4 and x = 5: a depth-1 tree splits there (wherever the
  // bootstrap left the neighbouring rows) and predicts each side's label exactly.
  Matrix x(10, 1), y(10, 1);
  for (int i = 0; i < 10; ++i) {
    x(i, 0) = i;
    y(i, 0) = i <= 4 ? 0.0 : 1.0;
  }
  for (std::uint64_t seed = 0; seed < 5; ++seed) {
    auto rf = RegressorRegistry::global().create("random_forest", {"trees=1", "max_depth=1"});
    rf->fit(x, y, seed);
    const Matrix p = rf->predict(x);
    for (int i = 0; i < 10; ++i)
      if (i <= 3 || i >= 6) {
        EXPECT_EQ(p(i, 0), y(i, 0)) << "seed " << seed << " row " << i;
      }
  }
}

TEST(RandomForest, RejectsMoreFeaturesPerSplitThanInputs) {
  Matrix y;
  const Matrix x = noisy_sine(50, &y, 2);
  auto rf = RegressorRegistry::global().create("random_forest", {"features=5"});
  try {
    rf->fit(x, y, 0);
    FAIL() << "features=5 accepted for 4 inputs";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr("random_forest: parameter features = 5 exceeds the 4 input columns"));
  }
}

TEST(RandomForest, RejectsAStoredTreeThatWouldLoop) {
  Matrix y;
  const Matrix x = noisy_sine(200, &y, 3);
  auto rf = RegressorRegistry::global().create("random_forest", {"trees=2"});
  rf->fit(x, y, 0);
  std::string payload = rf->save_payload();
  // Payload: magic (8), count (8), tree sizes (shape 16 + 4 doubles), node shape (16), then
  // rows of (feature, threshold, left, right, value). Point the root's left child at itself.
  const std::size_t root_left = 8 + 8 + 16 + 4 * 8 + 16 + 2 * 8;
  const double self = 0.0;
  std::memcpy(payload.data() + root_left, &self, sizeof self);
  auto fresh = RegressorRegistry::global().create("random_forest", {"trees=2"});
  try {
    fresh->load_payload(payload, 4, 2);
    FAIL() << "a looping tree was loaded";
  } catch (const std::exception& e) {
    EXPECT_THAT(e.what(), HasSubstr("random_forest: model payload node 0 holds 0"));
  }
}

}  // namespace
}  // namespace dicestack
