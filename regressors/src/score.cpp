#include <dicestack/regressors/score.hpp>

#include <dicestack/datasets/metrics.hpp>

namespace dicestack {

Score score(const Model& model, const Split& split) {
  const auto sigma = column_sigma(split.train.y);
  Score s;
  s.train_error = scaled_l1_error(split.train.y, model.predict(split.train.x), sigma);
  if (split.test.rows() > 0) s.test_error = scaled_l1_error(split.test.y, model.predict(split.test.x), sigma);
  s.split = split.description;
  return s;
}

Score score(const Model& model, const DemoSplit& split) { return score(model, split.matrices(model.features())); }

}  // namespace dicestack
