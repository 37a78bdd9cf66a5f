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
#include <dicestack/core/rng.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// none: the policy sees the observations; kalman: KalmanEstimator's estimate; particle:
/// ParticleEstimator's.
enum class EstimatorKind { none, kalman, particle };

/// Which estimator, and its settings: parsed once, at the edge, from `--estimator NAME`.
struct EstimatorConfig {
  EstimatorKind kind = EstimatorKind::none;
  /// The model's error in one control step, as a multiple of the simulator's own one-step error
  /// from true states (estimator.cpp; `dicestack bench estimator` prints it), > 0: larger trusts
  /// the sensor more, smaller the simulator. 3 did best of 1, 3, 10 and 30 on tuning seeds.
  double model_error = 3.0;
  /// particle: how many simulated worlds the filter keeps (`particle:N`), 1 to kMaxParticles.
  int particles = 64;
  /// particle: the model's error, in the same units. The particles must spread as far as a
  /// contact-rich swing carries runs of the simulator from one another, far beyond its one-step
  /// error from true states: 30 did best of 3, 10, 30, 100 and 300 (docs/notebook/2026-11-28-estimator.md).
  double particle_model_error = 30.0;
  /// kalman: under a delay with exact observations, forecast in the friction the observations
  /// show rather than the nominal one (KalmanEstimator's bank of 27 worlds).
  bool identify_friction = true;
};

/// How near an arm's model must stand to what the sensor gave to keep running, relative to each
/// number (plus 1): a few times the float rounding Box2D keeps its bodies in (Estimator::agrees).
inline constexpr double kArmAgreement = 1e-6;

/// The most particles `particle:N` takes: each is a world of its own (kEstimatorWorldBytes)
/// stepped at every control step (about 30 us), so 4096 hold about 650 MB and take about 40 s
/// per episode.
inline constexpr int kMaxParticles = 4096;

/// The estimators by name: none, kalman, particle.
const std::vector<std::string>& estimator_names();
/// The estimator of `name` with its default settings (`particle:N`: N particles); throws
/// ConfigError naming the choices, or the count's range.
EstimatorConfig estimator_config(std::string_view name);

/// Bytes one world of an estimator holds, measured: 1024 particles peak 158 MB above one
/// (docs/robustness.md, "The particle filter").
inline constexpr double kEstimatorWorldBytes = 160e3;

/// The friction scales the Kalman filter's bank tries for each material (KalmanEstimator).
inline constexpr std::array<double, 3> kFrictionScales{0.8, 1.0, 1.2};

/// The most memory one episode's estimator of `config` holds, in bytes (0 for none): what a
/// caller running many episodes at once checks (require_memory) before any work.
double estimator_bytes(const EstimatorConfig& config);

/// The simulator's error over one control step in state number k, in its own units (RMS from
/// true states; the filters' process noise is a multiple of it).
double model_error_of(std::size_t k);

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
  /// The arm's links in the Kalman filter's world of the last estimate (zeros for the floating
  /// cup, and from the particle filter): a policy in joint torques, whose law reads the links,
  /// acts on these with the estimate.
  const ArmLinks& links() const { return links_; }
  /// For a policy in joint torques on an arm, the links its joint encoders read now (exact and at
  /// once), given before start() and before each update(): the Kalman filter's model, rebuilt at
  /// an estimate, then holds the links read at the step it stands for, and the cup where they
  /// hold it; from the 24 numbers alone it would take the arm's rest posture.
  void read_encoders(const ArmLinks& now) { encoders_.push_back(now); }

 protected:
  /// Rebuilds `world` at `state` (with the links read at `step`, when the encoders were read);
  /// returns the state it then stands at: `state` itself, or on an arm with encoders its cup
  /// where the links hold it.
  State rebuild(World& world, const State& state, int step) const;
  /// True when a model's state and what the sensor gave agree, so the model keeps running (its
  /// contacts warm). Exactly, without encoders. With them, to within kArmAgreement of each
  /// number: a model rebuilt from the encoders stands within float rounding and the joints'
  /// slack of the world, never exactly on it, and a rebuild at every step would lose the
  /// contacts' warm-starting for nothing.
  bool agrees(const State& model, const State& sensed) const;

  ArmLinks links_{};
  std::vector<ArmLinks> encoders_;  // the links read at each step from the start (a torque policy on an arm)
};

/// What a robot's own command queue knows under delays, for an estimator: the commands chosen
/// but not run yet (a command delay), and those that ran since the step the newest observation
/// shows (an observation delay), which the estimate of that step must be moved through.
class CommandTimeline {
 public:
  /// `actions`: the kind the policy answers in, whose zeros run before its first choice lands.
  CommandTimeline(int action_delay, int observation_delay, ActionKind actions = ActionKind::cup)
      : action_delay_(action_delay), observation_delay_(observation_delay), actions_(actions) {}
  /// A new episode: action_delay zero commands queued (no torque on an arm's joints), nothing run.
  void start();
  /// Records the choice of the step just taken; true when the newest observation now shows a
  /// step later than the estimate stands at (move it through take_ran() first).
  bool choose(const Action& chosen);
  /// The command that ran at the estimate's step; the estimate's step moves on by one.
  Action take_ran();
  /// Steps `world` on through what ran since the estimate's step, then what is queued.
  void run_on(World& world) const;
  bool empty() const { return since_.empty() && queue_.empty(); }
  /// The step the estimate stands at (the newest observation's).
  int lagged_step() const { return lagged_step_; }

 private:
  int action_delay_, observation_delay_;
  ActionKind actions_;
  int steps_ = 0;         // control steps taken
  int lagged_step_ = 0;   // the step the estimate stands at
  std::deque<Action> queue_;  // chosen, not run yet
  std::deque<Action> since_;  // what ran from lagged_step_ to now, in order
};

/// A Kalman filter whose prediction is the simulator. It keeps an estimate of the state the
/// newest observation shows (observation_delay steps ago): each step it steps that estimate
/// through the simulator with the action that ran then, and corrects it towards the observation
/// with the gain of a Kalman filter per pose number and its velocity (the pair's covariance
/// moved as a pose integrating its velocity, plus the model's error, against the sensor's
/// noise). The current state is that estimate simulated forward through the actions that ran
/// since, and through the commands queued but not run yet (a command delay: the state the next
/// action lands in). Contacts are the simulator's: a die riding in the cup is predicted as
/// such. The model is rebuilt only where corrected, so without sensor noise, in the nominal
/// world, it runs as the world does and makes up a delay exactly (for a policy in joint
/// torques on an arm, to within kArmAgreement: Estimator::agrees).
///
/// Under a delay its forecast runs several steps in a physics it does not know, and the friction
/// moves it most (a die sliding in the cup or on the table). With exact observations and a delay
/// it keeps the world at kFrictionScales of the nominal friction for the dice, the cup and the
/// walls apart (27 worlds), each stepped as the model is, and forecasts with the one whose
/// one-step predictions have matched the observations best (not for a policy in joint torques,
/// where the bank was not measured). Under sensor noise the bank is not kept: the noise
/// outweighs what tells the frictions apart, and choosing among them measured worse
/// (docs/robustness.md, "The estimator").
class KalmanEstimator final : public Estimator {
 public:
  /// `model`: the nominal world; `draw`: the episode's sensing and command delays and its
  /// sensor's noise (nothing else of it is read); `actions`: the kind the policy answers in.
  KalmanEstimator(const WorldConfig& model, const PerturbationDraw& draw, const EstimatorConfig& config,
                  ActionKind actions = ActionKind::cup);
  State start(const State& observed) override;
  State update(const Action& chosen, const State& observed) override;

 private:
  struct Covariance {
    double pp = 0.0, pv = 0.0, vv = 0.0;  // a pose number's variance, its covariance with its velocity, the velocity's
  };
  void predict();
  void correct(const State& observed);
  void choose_model(const State& observed);
  State ahead();

  std::vector<World> models_;     // the nominal world first, then the bank's other frictions (if kept)
  std::vector<State> predicted_;  // each model's prediction of the newest observation (the state it stands at)
  std::vector<double> misfit_;    // each model's discounted negative log-likelihood of the observations
  std::size_t chosen_ = 0;        // the model that forecasts
  double dt_;
  CommandTimeline timeline_;
  State sensor_variance_{};
  State process_variance_{};
  State lagged_{};  // the estimate of the state the newest observation shows
  std::array<Covariance, 12> covariance_{};  // per pose number and its velocity
};

/// A particle filter whose motion model is the simulator, for the contact phases a filter per
/// number cannot follow: each particle is a world of its own, stepped with the action that ran
/// (its contacts the simulator's, a die riding in the cup rides in every particle), then drawn
/// towards the observation as the optimal proposal for Gaussian noise does (the model's error
/// against the sensor's, number by number) and weighted by how likely the observation was from
/// it; resampled (systematically) when the weights' effective count falls below half. The
/// estimate is the weighted mean. docs/robustness.md, "The particle filter". Delays are made
/// up as the Kalman filter makes them up: the cloud stands at the newest observation's step,
/// and the mean is simulated forward through what ran since and what is queued. Seeded by the
/// episode's noise stream, so the same on any number of threads or ranks.
class ParticleEstimator final : public Estimator {
 public:
  ParticleEstimator(const WorldConfig& model, const PerturbationDraw& draw, const EstimatorConfig& config,
                    ActionKind actions = ActionKind::cup);
  State start(const State& observed) override;
  State update(const Action& chosen, const State& observed) override;

 private:
  void predict();
  void weigh(const State& observed);
  void resample_if_starved();
  State mean() const;
  State ahead();

  CommandTimeline timeline_;
  State sensor_sigma_{};
  State process_sigma_{};
  std::uint64_t seed_;
  Rng rng_{0};
  std::vector<World> worlds_;    // one per particle
  std::vector<State> states_;    // their states
  std::vector<double> weights_;  // their weights, summing to 1
  World scratch_;                // where the mean is run on through the delays
  bool predicted_ = false;       // the particles were stepped since the last observation
};

/// The estimator of `config` for one episode (nullptr for none, and when the draw's sensing and
/// command timing are nominal: the policy then sees the state itself; particle without sensor
/// noise is the Kalman filter, which makes up the delays exactly). Each episode needs its own:
/// start() first. `actions`: the kind the policy answers in (an arm's joint torques, or the cup's).
std::unique_ptr<Estimator> make_estimator(const EstimatorConfig& config, const WorldConfig& model,
                                          const PerturbationDraw& draw, ActionKind actions = ActionKind::cup);

}  // namespace dicestack
