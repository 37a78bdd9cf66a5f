#pragma once
// A trained model: a feature map, a regressor with the standardisers of its inputs and labels,
// and the file format that stores it (STYLE 10, docs/formats.md): a one-line JSON header (format,
// version, dicestack version, regressor, parameters, feature map, standardisers, dimensions,
// payload size and checksum, training record) followed by the backend's payload. A Python
// regressor's model keeps its estimator pickled in a second file (PickledRegressor).
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/standardizer.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/regressors/registry.hpp>

namespace dicestack {

inline constexpr const char* kModelFormat = "dicestack-model";
/// 2 added the feature map ("features", "features_version", "input_dim", "input_names");
/// version 1 files are read as the "state" map. 3: the map may read the arm's links and answer
/// its four joint torques ("action_dim" 4); a model whose map does neither is written as version 2.
inline constexpr int kModelFormatVersion = 3;

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

  /// Hot path: the action after `history` (features, standardise, predict_row, unstandardise,
  /// the map's answer turned into an action); no allocation.
  Action act(const History& history) const;
  /// The action for a lone state, seen as the first of an episode (t = 0, its own start).
  Action act(const State& state) const;
  /// The regressor's answers for every row of `rows` (N x features().width(), feature rows): the
  /// actions, or for a "/velocity" map the cup velocities to set (FeatureMap::target).
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

/// A regressor whose fitted model is a Python object (dicestack.register_regressor). save_model
/// writes it pickled to MODEL.pkl (pickle_path) beside the model file, whose payload is a small
/// record (is_pickled_payload) with the pickle's size and FNV-1a that ties the two together.
/// Unpickling runs code, so load_model reads such a model only when given a PickleLoader (the
/// Python package's load_model(path, allow_pickle=True)); the command line refuses it.
class PickledRegressor : public Regressor {
 public:
  using Regressor::Regressor;
  /// The fitted object, pickled. Requires a fitted model.
  virtual std::string pickle() const = 0;
  /// What the pickle holds, for messages: "sklearn.ensemble._forest.RandomForestRegressor".
  virtual std::string object_type() const = 0;

 private:
  std::string do_save() const final;  ///< the payload record of pickle()
};

/// Where save_model puts a PickledRegressor's pickle: the model's path with ".pkl" appended.
std::filesystem::path pickle_path(const std::filesystem::path& model);

/// True for a payload written for a PickledRegressor (a JSON record with format
/// "dicestack-pickled-regressor").
bool is_pickled_payload(std::string_view payload);

/// Which existing file at pickle_path(model) save_model may replace: the pickle that the
/// dicestack model file now at `model` was saved with (same size and FNV-1a). Anything else (a
/// user's file, a pickle of another model) is refused.
Ownership pickle_ownership(const std::filesystem::path& model);

/// Makes the regressor of a pickled model from its registry name, its parameters
/// ("key=value", as saved) and the pickle's bytes (already checked against the model file).
using PickleLoader = std::function<std::unique_ptr<Regressor>(const std::string& name, const std::vector<std::string>& params,
                                                              const std::string& pickle)>;

/// Which existing files save_model may replace: a first line that is JSON with
/// "format": "dicestack-model". Also what checkpoint cleanup removes.
Ownership model_ownership();

/// Writes a model file atomically. An existing file at `path` that is not a dicestack model is
/// refused (InputError naming it) and left as it is. Throws InputError. A PickledRegressor's
/// pickle goes to pickle_path(path) first (refused unless pickle_ownership(path) recognises an
/// existing file there); saving another model over a pickled one removes the old pickle.
void save_model(const Model& model, const std::filesystem::path& path);

/// The bytes save_model would write for `model` (not pickled: InputError), as one string: how a
/// model refitted on the root reaches the other ranks of a Cluster (parse_model_file reads it).
std::string model_to_bytes(const Model& model);

/// Reads a model file (any version up to kModelFormatVersion), checking format, version,
/// regressor (registered?), parameters, feature map (known, same version, same width as the
/// regressor's input), dimensions, standardisers, payload size and checksum.
/// Throws InputError naming the file and what is wrong (or ConfigError for an unknown regressor).
/// A pickled model (see PickledRegressor) is read only through `pickles`, after its pickle is
/// checked against the model file; without one it is refused with an InputError that says why.
Model load_model(const std::filesystem::path& path, const RegressorRegistry& registry = RegressorRegistry::global(),
                 const PickleLoader& pickles = {});

/// What load_model does with a model file's bytes, for callers that hold them (the fuzzer,
/// tests): `where` (a path) starts every message. Same checks, same errors.
Model parse_model_file(std::string_view bytes, const std::string& where,
                       const RegressorRegistry& registry = RegressorRegistry::global(), const PickleLoader& pickles = {});

}  // namespace dicestack
