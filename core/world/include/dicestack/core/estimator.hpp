#pragma once
// A state estimator between the sensors and the policy: from what the sensors give (noisy,
// late) and the actions sent, an estimate of the current state. Its motion model is the
// simulator of the nominal world, the robot's model: it knows neither the episode's physics
// draw nor its actuation noise. It knows what a robot knows of its own sensors and commands:
// the observation's latency (its timestamp), the length of its command queue and its sensor's
// noise spread. docs/robustness.md, "The estimator".
#include <array>
#include <deque>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/perturbation.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// none: the policy sees the observations; kalman: KalmanEstimator's estimate.
enum class EstimatorKind { none, kalman };

/// Which estimator, and its settings: parsed once, at the edge, from `--estimator NAME`.
struct EstimatorConfig {
  EstimatorKind kind = EstimatorKind::none;
  /// The model's error in one control step, as a multiple of the simulator's own one-step error
  /// from true states (estimator.cpp; `dicestack bench estimator` prints it), > 0: larger trusts
  /// the sensor more, smaller the simulator. 3 did best of 1, 3, 10 and 30 on tuning seeds.
  double model_error = 3.0;
};

/// The estimators by name: none, kalman.
const std::vector<std::string>& estimator_names();
/// The estimator of `name` with its default settings; throws ConfigError naming the choices.
EstimatorConfig estimator_config(std::string_view name);

/// True when `p` perturbs what a policy senses (observation noise or delay) or when its commands
/// run (action delay): only then does an estimator run.
bool senses(const Perturbation& p);

/// What a policy is given instead of the raw observation, one episode at a time.
class Estimator {
 public:
  virtual ~Estimator() = default;
  /// The episode's first observation; returns the estimate of the start.
  virtual State start(const State& observed) = 0;
  /// After one control step: what the policy chose for it (clipped to the world's limits) and
  /// what the sensor gave after it; returns the estimate of the state the next choice acts on:
  /// under a command delay, the state it lands in (what ran, plus what is queued), so a policy
  /// trained without the delay acts on the state its action meets. A policy's clock stays the
  /// count of its own choices: the choice lands after as many of them as it would without.
  virtual State update(const Action& chosen, const State& observed) = 0;
};

/// A Kalman filter whose prediction is the simulator. It keeps an estimate of the state the
/// newest observation shows (observation_delay steps ago): each step it steps that estimate
/// through the simulator with the action that ran then, and corrects it towards the observation
/// with the gain of a Kalman filter per pose number and its velocity (the pair's covariance
/// moved as a pose integrating its velocity, plus the model's error, against the sensor's
/// noise). The current state is that estimate simulated forward through the actions that ran
/// since, and through the commands queued but not run yet (a command delay: the state the next
/// action lands in). Contacts are the simulator's: a die riding in the cup is predicted as such. The model
/// is rebuilt only where corrected, so without sensor noise, in the nominal world, it runs as
/// the world does and makes up a delay exactly.
class KalmanEstimator final : public Estimator {
 public:
  /// `model`: the nominal world; `draw`: the episode's sensing and command delays and its
  /// sensor's noise (nothing else of it is read).
  KalmanEstimator(const WorldConfig& model, const PerturbationDraw& draw, const EstimatorConfig& config);
  State start(const State& observed) override;
  State update(const Action& chosen, const State& observed) override;

 private:
  struct Covariance {
    double pp = 0.0, pv = 0.0, vv = 0.0;  // a pose number's variance, its covariance with its velocity, the velocity's
  };
  void predict();
  void correct(const State& observed);
  State ahead();

  World model_;
  double dt_;
  int observation_delay_;
  int action_delay_;
  State sensor_variance_{};
  State process_variance_{};
  State lagged_{};  // the estimate of the state the newest observation shows
  std::array<Covariance, 12> covariance_{};  // per pose number and its velocity
  int steps_ = 0;   // control steps taken
  int lagged_step_ = 0;
  std::deque<Action> queue_;  // chosen, not run yet (the command delay)
  std::deque<Action> since_;  // what ran from lagged_step_ to now, in order
};

/// The estimator of `config` for one episode (nullptr for none, and when the draw's sensing and
/// command timing are nominal: the policy then sees the state itself). Each episode needs its own: start() first.
std::unique_ptr<Estimator> make_estimator(const EstimatorConfig& config, const WorldConfig& model,
                                          const PerturbationDraw& draw);

}  // namespace dicestack
