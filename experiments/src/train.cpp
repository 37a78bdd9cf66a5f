#include <dicestack/experiments/train.hpp>

#include <chrono>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/record.hpp>

namespace dicestack {

namespace {

// The map a request trains: the one it names, else the learner's default (in joint torques when
// the controller says so). A map that contradicts the controller is refused.
std::string train_features(const TrainRequest& request) {
  const bool torques = request.controller == "joint_torque";
  if (!request.controller.empty() && !torques && request.controller != "cup")
    throw ConfigError("train: controller \"" + request.controller + "\" is not one of cup, joint_torque");
  if (request.features.empty()) {
    const std::string fallback = default_features(request.learner, request.learner_options);
    return torques ? torque_map_name(fallback) : fallback;
  }
  const FeatureMap& given = feature_map(request.features);
  if (!request.controller.empty() && (given.action_kind() == ActionKind::joint_torque) != torques)
    throw ConfigError("train: feature map \"" + given.name() + "\" answers " +
                      std::string(action_kind_name(given.action_kind())) + " actions, not the " + request.controller +
                      " controller's");
  return given.name();
}

}  // namespace

std::string check_train_settings(const TrainRequest& request) {
  const auto learner = LearnerRegistry::global().create(request.learner, request.learner_options);
  // An unknown regressor or a bad --set value would otherwise surface only at the first fit,
  // after DART had recorded its episodes.
  RegressorRegistry::global().create(request.regressor, request.regressor_sets);
  const FeatureMap& features = feature_map(train_features(request));
  check_map_world(features, request.world);
  require_learnable_map(request.learner, learner->params(), features);
  for (const auto& [key, value] : learner->params().as_text())
    if (key == "perturb")
      require_labellable(learner_perturbation(learner->params(), request.world, request.learner), features, request.learner,
                         request.learner == "dagger");
  if (request.split != "episodes" && request.split != "none")
    throw ConfigError("split \"" + request.split + "\" is not one of episodes, none");
  return features.name();
}

TrainReport train_model(const TrainRequest& request) {
  const FeatureMap& features = feature_map(check_train_settings(request));
  const auto learner = LearnerRegistry::global().create(request.learner, request.learner_options);
  if (request.demos.empty())
    throw InputError((request.demos_name.empty() ? std::string("the demonstrations") : request.demos_name) +
                     ": no episode to train on");
  const DemoSplit split(request.demos, request.split);
  LearnContext c;
  c.demos = split.train();
  c.held_out = split.held_out();
  c.world = request.world;
  c.regressor = request.regressor;
  c.regressor_sets = request.regressor_sets;
  c.features = features.name();
  c.seed = request.seed;
  c.threads = request.threads;
  c.checkpoint_dir = request.checkpoint_dir;
  c.resume = request.resume;
  c.progress = request.progress;
  c.cluster = request.cluster;

  TrainReport report;
  report.features = features.name();
  const auto t0 = std::chrono::steady_clock::now();
  report.result = learner->learn(c);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Model& model = *report.result.model;
  model.record["learner"] = request.learner;
  std::string options;  // as the run used them: a tracker option not given shows its preset's value
  for (const auto& [key, value] : effective_options(*learner)) options += (options.empty() ? "" : ", ") + key + "=" + value;
  model.record["learner_options"] = options;
  model.record["demos"] = request.demos_name;
  std::string names;  // the recordings it learned from, by name
  for (const auto& e : c.demos) names += (names.empty() ? "" : ", ") + e.name;
  model.record["recordings"] = std::to_string(c.demos.size()) + ": " + names;
  model.record["split"] = request.split;
  model.record["seed"] = std::to_string(request.seed);
  if (!model.features().reads_links() && model.features().action_kind() == ActionKind::cup) report.score = score(model, split);
  return report;
}

}  // namespace dicestack
