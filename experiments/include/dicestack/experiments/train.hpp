#pragma once
// Training a model the way `dicestack train` does, shared by the command line and the Python
// package: what a demonstration name stands for, the episode split, the learner run, the
// training record written into the model, and its eq. 9 errors.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>  // resolve_demo_set, which every caller of train needs first
#include <dicestack/regressors/score.hpp>

namespace dicestack {

/// What `dicestack train` asks for.
struct TrainRequest {
  WorldConfig world;
  std::vector<Episode> demos;               ///< the whole set, in file-name order (split below)
  std::string demos_name;                   ///< recorded in the model: the folder, or how the episodes were given
  std::string regressor;
  std::vector<std::string> regressor_sets;  ///< "key=value" for the regressor
  std::string learner = "bc";
  std::vector<std::string> learner_options; ///< "key=value" for the learner
  std::string features;                     ///< feature map; empty: the learner's default
  /// "cup" or "joint_torque": what the policy's actions are for; empty: what the map answers.
  /// joint_torque without a map takes the learner's default in torques (torque_map_name).
  std::string controller;
  /// "episodes": train on episodes i % 5 != 4, report test error and give the rest to the
  /// learner as held-out demonstrations; "none": train on all.
  std::string split = "episodes";
  std::uint64_t seed = 0;
  int threads = 0;                          ///< 0 = all cores; results do not depend on it
  std::filesystem::path checkpoint_dir;     ///< empty: no checkpoints
  bool resume = false;
  std::function<void(const Progress&)> progress;  ///< may be empty
  /// The ranks that share the work (LearnContext::cluster); the same model on every rank.
  Cluster* cluster = &local_cluster();
};

/// What came out: the model (its record filled in), its learning curve and errors.
struct TrainReport {
  LearnResult result;
  std::string features;              ///< the feature map used
  double seconds = 0.0;              ///< the learner's wall time
  /// Eq. 9 on the training and held-out episodes; empty when the map cannot read them (a torque
  /// policy: the recordings hold cup actions and no arm links).
  std::optional<Score> score;
};

/// Checks what a request names, without its demonstrations: the learner and its options (a
/// `perturb` level or file against the world), the regressor and its settings, the feature map
/// (and an "/ahead" map's world) and the split. Throws ConfigError naming the first bad one;
/// returns the feature map's name. Callers run it before reading any demonstration.
std::string check_train_settings(const TrainRequest& request);

/// check_train_settings, then splits, runs the learner and records learner, options,
/// demonstrations, split and seed in the model. Throws InputError when the split leaves nothing
/// to train on.
TrainReport train_model(const TrainRequest& request);

}  // namespace dicestack
