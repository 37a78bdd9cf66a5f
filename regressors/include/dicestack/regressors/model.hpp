#pragma once
// A trained model: a feature map, a regressor with the standardisers of its inputs and labels,
// and the file format that stores it (STYLE 10, docs/formats.md): a one-line JSON header (format,
// version, dicestack version, regressor, parameters, feature map, standardisers, dimensions,
// payload size and checksum, training record) followed by the backend's payload.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <string_view>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/datasets/standardizer.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack {

inline constexpr const char* kModelFormat = "dicestack-model";
/// 2 added the feature map ("features", "features_version", "input_dim", "input_names");
/// version 1 files are read as the "state" map.
inline constexpr int kModelFormatVersion = 2;

/// Feature map + regressor + standardisers: maps what an episode has shown to a raw action.
class Model {
 public:
  Model(std::unique_ptr<Regressor> regressor, Standardizer x, Standardizer y,
        const FeatureMap& features = state_features());

  /// Fits the standardisers on the feature rows `x` (N x features.width(), e.g. from
  /// make_dataset(episodes, features)) and the regressor on the standardised rows. Constant
  /// columns are reported in `warnings` (if given). Throws InputError on a width mismatch.
  static Model train(std::unique_ptr<Regressor> regressor, const Matrix& x, const Matrix& y, std::uint64_t seed,
                     std::vector<std::string>* warnings = nullptr, const FeatureMap& features = state_features());

  /// Hot path: the action after `history` (features, standardise, predict_row, unstandardise);
  /// no allocation.
  Action act(const History& history) const;
  /// The action for a lone state, seen as the first of an episode (t = 0, its own start).
  Action act(const State& state) const;
  /// Actions for every row of `rows` (N x features().width(), feature rows).
  Matrix predict(const Matrix& rows) const;

  const FeatureMap& features() const { return *features_; }

  const Regressor& regressor() const { return *regressor_; }
  const Standardizer& x_scaler() const { return x_; }
  const Standardizer& y_scaler() const { return y_; }

  /// Free-form training record saved in the header (learner, demonstrations, split, seed...).
  std::map<std::string, std::string> record;

 private:
  std::unique_ptr<Regressor> regressor_;
  const FeatureMap* features_;
  Standardizer x_;
  Standardizer y_;
};

/// Which existing files save_model may replace: a first line that is JSON with
/// "format": "dicestack-model". Also what checkpoint cleanup removes.
Ownership model_ownership();

/// Writes a model file atomically. An existing file at `path` that is not a dicestack model is
/// refused (InputError naming it) and left as it is. Throws InputError.
void save_model(const Model& model, const std::filesystem::path& path);

/// Reads a model file (any version up to kModelFormatVersion), checking format, version,
/// regressor (registered?), parameters, feature map (known, same version, same width as the
/// regressor's input), dimensions, standardisers, payload size and checksum.
/// Throws InputError naming the file and what is wrong (or ConfigError for an unknown regressor).
Model load_model(const std::filesystem::path& path, const RegressorRegistry& registry = RegressorRegistry::global());

/// What load_model does with a model file's bytes, for callers that hold them (the fuzzer,
/// tests): `where` (a path) starts every message. Same checks, same errors.
Model parse_model_file(std::string_view bytes, const std::string& where,
                       const RegressorRegistry& registry = RegressorRegistry::global());

}  // namespace dicestack
