#pragma once
// A model's eq. 9 errors on a demonstration split: the one place train and test error are
// computed (train, evaluate --demos, the leaderboard, bench regressors, the Python package).
#include <optional>
#include <string>

#include <dicestack/datasets/dataset.hpp>
#include <dicestack/regressors/model.hpp>

namespace dicestack {

struct Score {
  double train_error = 0.0;          ///< eq. 9 on the training rows, sigma from their labels
  std::optional<double> test_error;  ///< the same on the test rows; none when there are none
  std::string split;                 ///< the split's description
};

/// Scores `model` on `split` (matrices in the model's own feature map).
Score score(const Model& model, const Split& split);

/// Scores `model` on `split` seen through the model's feature map.
Score score(const Model& model, const DemoSplit& split);

}  // namespace dicestack
