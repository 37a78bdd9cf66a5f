#pragma once
// Policies: what acts in the world. A learned policy is a Model (regressor + standardisers);
// the environment clips every action to the world's limits.
#include <memory>
#include <string>

#include <dicestack/core/types.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/regressors/model.hpp>

namespace dicestack {

/// Chooses an action for a state. `act` is called once per control step, in order, from one
/// thread per policy object; `reset` starts an episode.
class Policy {
 public:
  virtual ~Policy() = default;
  virtual void reset(std::uint64_t seed) { (void)seed; }
  virtual Action act(const State& state) = 0;
  virtual std::string name() const = 0;
};

/// A trained model acting on its own (thread-safe to share: each caller wraps it).
class ModelPolicy final : public Policy {
 public:
  explicit ModelPolicy(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  Action act(const State& state) override { return model_->act(state); }
  std::string name() const override { return model_->regressor().name(); }
  const Model& model() const { return *model_; }

 private:
  std::shared_ptr<const Model> model_;
};

/// Replays a demonstration's actions in order (paper VI-A), then does nothing.
class PlaybackPolicy final : public Policy {
 public:
  explicit PlaybackPolicy(const Episode& episode) : actions_(episode.actions) {}
  void reset(std::uint64_t) override { t_ = 0; }
  Action act(const State&) override { return t_ < actions_.size() ? actions_[t_++] : Action{0.0, 0.0, 0.0}; }
  std::string name() const override { return "playback"; }

 private:
  std::vector<Action> actions_;
  std::size_t t_ = 0;
};

}  // namespace dicestack
