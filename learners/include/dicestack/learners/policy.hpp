#pragma once
// Policies: what acts in the world. Every policy acts on what its episode has shown it (the
// states so far, the actions the world applied, the step index: a History); a learned policy
// is a Model (feature map + regressor + standardisers); an automatic expert may in addition
// read the environment it acts in (mpc simulates from its snapshot), a learned policy never does.
// The environment clips every action to the world's limits.
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include <dicestack/core/env.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/regressors/model.hpp>

namespace dicestack {

/// What a rollout records for a step when it is not the action taken: DAgger's mixture takes the
/// learner's action but records the expert's label.
struct Labelled {
  Action label{};
  StepSource source = StepSource::expert;
};

/// Chooses an action after a history. `act` is called once per control step, in order, from
/// one thread per policy object; `reset` starts an episode.
class Policy {
 public:
  virtual ~Policy() = default;
  virtual void reset(std::uint64_t seed) { (void)seed; }
  /// The environment the next episode runs in, before reset (rollout calls it): a policy that
  /// simulates, an expert, reads it; the others ignore it.
  virtual void attach(const DiceEnv& env) { (void)env; }
  virtual Action act(const History& history) = 0;
  virtual std::string name() const = 0;
  /// The label of the step `act` just chose, if it differs from the action (default: none).
  virtual std::optional<Labelled> label() const { return std::nullopt; }
};

/// A trained model acting on its own (thread-safe to share: each caller wraps it).
class ModelPolicy final : public Policy {
 public:
  explicit ModelPolicy(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  Action act(const History& history) override { return model_->act(history); }
  std::string name() const override { return model_->regressor().name(); }
  const Model& model() const { return *model_; }

 private:
  std::shared_ptr<const Model> model_;
};

/// Replays a demonstration's actions by step index (paper VI-A), then does nothing.
class PlaybackPolicy final : public Policy {
 public:
  explicit PlaybackPolicy(const Episode& episode) : actions_(episode.actions) {}
  Action act(const History& history) override {
    return history.t() < actions_.size() ? actions_[history.t()] : Action{0.0, 0.0, 0.0};
  }
  std::string name() const override { return "playback"; }

 private:
  std::vector<Action> actions_;
};

/// What an expert's feedback acts on: the world's own state (its privilege), or what the
/// rollout shows a policy (noisy or late under a perturbation's sensing).
enum class ExpertFeedback { world, observations };

/// An automatic expert acting in `env` (which must be the environment the rollout steps); its
/// feedback reads the world, or what the rollout shows a policy.
class ExpertPolicy final : public Policy {
 public:
  /// Acts in `env` until rollout attaches another.
  ExpertPolicy(Expert& expert, const DiceEnv& env, ExpertFeedback feedback = ExpertFeedback::world)
      : expert_(expert), env_(&env), feedback_(feedback) {}
  void attach(const DiceEnv& env) override { env_ = &env; }
  void reset(std::uint64_t seed) override { expert_.reset(seed); }
  Action act(const History& h) override {
    return expert_.act(*env_, h.pending, feedback_ == ExpertFeedback::observations ? &h.current() : nullptr);
  }
  std::string name() const override { return "expert " + expert_.name(); }

 private:
  Expert& expert_;
  const DiceEnv* env_;
  ExpertFeedback feedback_;
};

/// An expert of its own, acting in whichever environment rollout attaches (evaluation of an
/// expert, the robustness table). Its choices read the world itself; its feedback too, unless
/// told to act on the observations (Expert::act's `sensed`).
class OwnedExpertPolicy final : public Policy {
 public:
  explicit OwnedExpertPolicy(std::unique_ptr<Expert> expert, ExpertFeedback feedback = ExpertFeedback::world)
      : expert_(std::move(expert)), feedback_(feedback) {}
  void attach(const DiceEnv& env) override { env_ = &env; }
  void reset(std::uint64_t seed) override { expert_->reset(seed); }
  Action act(const History& h) override {
    if (!env_) throw std::logic_error("expert " + expert_->name() + ": no environment attached (roll it out with rollout())");
    return expert_->act(*env_, h.pending, feedback_ == ExpertFeedback::observations ? &h.current() : nullptr);
  }
  std::string name() const override { return "expert " + expert_->name(); }

 private:
  std::unique_ptr<Expert> expert_;
  ExpertFeedback feedback_;
  const DiceEnv* env_ = nullptr;
};

}  // namespace dicestack
