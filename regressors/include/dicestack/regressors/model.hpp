#pragma once
// A trained model: a regressor with the standardisers of its inputs and labels, and the file
// format that stores it (STYLE 10): a one-line JSON header (format, version, dicestack version,
// regressor, parameters, standardisers, dimensions, payload size and checksum, training
// record) followed by the backend's payload.
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/datasets/standardizer.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack {

inline constexpr const char* kModelFormat = "dicestack-model";
inline constexpr int kModelFormatVersion = 1;

/// Regressor + standardisers: maps a raw state to a raw action.
class Model {
 public:
  Model(std::unique_ptr<Regressor> regressor, Standardizer x, Standardizer y);

  /// Fits the standardisers on `train`'s rows and the regressor on the standardised rows.
  /// Constant columns are reported in `warnings` (if given).
  static Model train(std::unique_ptr<Regressor> regressor, const Matrix& x, const Matrix& y, std::uint64_t seed,
                     std::vector<std::string>* warnings = nullptr);

  /// Hot path: the action for one state (standardise, predict_row, unstandardise); no allocation.
  Action act(const State& state) const;
  /// Actions for every row of `states` (N x 24).
  Matrix predict(const Matrix& states) const;

  const Regressor& regressor() const { return *regressor_; }
  const Standardizer& x_scaler() const { return x_; }
  const Standardizer& y_scaler() const { return y_; }

  /// Free-form training record saved in the header (learner, demonstrations, split, seed...).
  std::map<std::string, std::string> record;

 private:
  std::unique_ptr<Regressor> regressor_;
  Standardizer x_;
  Standardizer y_;
};

/// Which existing files save_model may replace: a first line that is JSON with
/// "format": "dicestack-model". Also what checkpoint cleanup removes.
Ownership model_ownership();

/// Writes a model file atomically. An existing file at `path` that is not a dicestack model is
/// refused (InputError naming it) and left as it is. Throws InputError.
void save_model(const Model& model, const std::filesystem::path& path);

/// Reads a model file, checking format, version, regressor (registered?), parameters,
/// dimensions (24 state, 3 action values), standardisers, payload size and checksum.
/// Throws InputError naming the file and what is wrong (or ConfigError for an unknown regressor).
Model load_model(const std::filesystem::path& path, const RegressorRegistry& registry = RegressorRegistry::global());

}  // namespace dicestack
