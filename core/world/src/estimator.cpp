#include <dicestack/core/estimator.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

// A pose number and its velocity: the pairs the filter couples (a velocity's error moves the
// pose it integrates into).
struct Pair {
  std::size_t pose, velocity;
};

constexpr std::array<Pair, 12> make_pairs() {
  std::array<Pair, 12> out{};
  for (std::size_t j = 0; j < 3; ++j) out[j] = {j, state_index::kCupVx + j};
  for (std::size_t i = 0; i < kDiceCount; ++i)
    for (std::size_t j = 0; j < 3; ++j) out[3 + 3 * i + j] = {state_index::die(i) + j, state_index::die(i) + 3 + j};
  return out;
}
constexpr std::array<Pair, 12> kPairs = make_pairs();

// The simulator's error over one control step from a true state, RMS per state number in units
// of its spread (observation_spread()), over the built-in set's 15,110 steps (`dicestack bench
// estimator` prints it): rebuilding a scene from a state loses its contacts' warm-starting, so
// the dice's velocities (their contacts) are the least predictable and the cup's pose the most.
// The floor keeps every number's process noise above zero.
constexpr State kModelError{0.0000, 0.0011, 0.0001,                          // cup x, y, angle
                            0.0002, 0.0006, 0.0005, 0.0064, 0.0194, 0.0419,  // die 0 x, y, angle, vx, vy, w
                            0.0003, 0.0008, 0.0005, 0.0105, 0.0527, 0.0423,  // die 1
                            0.0002, 0.0005, 0.0005, 0.0038, 0.0150, 0.0472,  // die 2
                            0.0010, 0.0101, 0.0015};                         // cup vx, vy, w
constexpr double kModelErrorFloor = 1e-4;

// How much older observations count in a model's misfit (each step's is multiplied by this),
// and how much better (in nats) another model must fit before the forecast moves to it: a
// model chosen on one lucky step would flicker.
constexpr double kMisfitMemory = 0.9;
constexpr double kSwitchMargin = 5.0;

// The nominal world with its dice', cup's and walls' friction scaled by every combination of
// kFrictionScales but the nominal one.
std::vector<WorldConfig> other_frictions(const WorldConfig& model) {
  std::vector<WorldConfig> out;
  for (const double dice : kFrictionScales)
    for (const double cup : kFrictionScales)
      for (const double walls : kFrictionScales) {
        if (dice == 1.0 && cup == 1.0 && walls == 1.0) continue;
        WorldConfig& w = out.emplace_back(model);
        w.dice.friction *= dice;
        w.cup.friction *= cup;
        w.walls.friction *= walls;
      }
  return out;
}

}  // namespace

double model_error_of(std::size_t k) { return std::max(kModelError[k], kModelErrorFloor) * observation_spread()[k]; }

double estimator_bytes(const EstimatorConfig& config) {
  // The Kalman filter's model and, under a delay with exact observations, its friction bank.
  const double kalman = config.identify_friction ? std::pow(static_cast<double>(kFrictionScales.size()), 3) : 1.0;
  switch (config.kind) {
    case EstimatorKind::none: return 0.0;
    case EstimatorKind::kalman: break;
    case EstimatorKind::particle:  // the particles and the world the mean runs on in, or without noise the Kalman filter
      return std::max(config.particles + 1.0, kalman) * kEstimatorWorldBytes;
  }
  return kalman * kEstimatorWorldBytes;
}

const std::vector<std::string>& estimator_names() {
  static const std::vector<std::string> names{"none", "kalman", "particle"};
  return names;
}

bool senses(const Perturbation& p) {
  return p.observation_noise > 0.0 || p.observation_delay > 0 || p.action_delay > 0;
}

EstimatorConfig estimator_config(std::string_view name) {
  EstimatorConfig c;
  if (name == "none") return c;
  if (name == "kalman") {
    c.kind = EstimatorKind::kalman;
    return c;
  }
  constexpr std::string_view particle = "particle";
  if (name.substr(0, particle.size()) == particle && (name.size() == particle.size() || name[particle.size()] == ':')) {
    c.kind = EstimatorKind::particle;
    if (name.size() == particle.size()) return c;
    const std::string_view count = name.substr(particle.size() + 1);
    long long n = 0;
    const bool digits = !count.empty() && count.size() <= 6 &&
                        std::all_of(count.begin(), count.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
    if (digits) n = std::stoll(std::string(count));
    if (!digits || n < 1 || n > kMaxParticles)
      throw ConfigError("estimator \"" + std::string(name.substr(0, 60)) + "\": particle:N takes a count of particles from 1 to " +
                        std::to_string(kMaxParticles));
    c.particles = static_cast<int>(n);
    return c;
  }
  throw ConfigError("estimator \"" + std::string(name.substr(0, 60)) + "\" is not one of none, kalman, particle (particle:N)");
}

void CommandTimeline::start() {
  steps_ = lagged_step_ = 0;
  queue_.assign(static_cast<std::size_t>(action_delay_), Action::zeros(actions_));
  since_.clear();
}

bool CommandTimeline::choose(const Action& chosen) {
  queue_.push_back(chosen);
  since_.push_back(queue_.front());
  queue_.pop_front();
  ++steps_;
  // The observation shows the state of observation_delay steps ago (the start before then).
  return steps_ - observation_delay_ > lagged_step_;
}

Action CommandTimeline::take_ran() {
  const Action ran = since_.front();
  since_.pop_front();
  ++lagged_step_;
  return ran;
}

void CommandTimeline::run_on(World& world) const {
  for (const Action& a : since_) world.step(a);
  for (const Action& a : queue_) world.step(a);
}

KalmanEstimator::KalmanEstimator(const WorldConfig& model, const PerturbationDraw& draw, const EstimatorConfig& config,
                                 ActionKind actions)
    : dt_(model.physics.control_dt), timeline_(draw.action_delay, draw.observation_delay, actions) {
  for (std::size_t k = 0; k < kStateDim; ++k) {
    sensor_variance_[k] = draw.observation_noise[k] * draw.observation_noise[k];
    const double q = config.model_error * model_error_of(k);
    process_variance_[k] = q * q;
  }
  const bool exact = std::all_of(sensor_variance_.begin(), sensor_variance_.end(), [](double v) { return v == 0.0; });
  std::vector<WorldConfig> worlds{model};
  if (config.identify_friction && exact && (draw.action_delay > 0 || draw.observation_delay > 0) &&
      actions == ActionKind::cup)
    for (const WorldConfig& w : other_frictions(model)) worlds.push_back(w);
  models_.reserve(worlds.size());
  for (const WorldConfig& w : worlds) models_.emplace_back(w);
  predicted_.assign(models_.size(), State{});
  misfit_.assign(models_.size(), 0.0);
}

State Estimator::rebuild(World& world, const State& state, int step) const {
  if (encoders_.empty()) {
    world.set_state(state);
    return state;
  }
  world.set_state(state, encoders_.at(static_cast<std::size_t>(step)));
  return world.state();
}

bool Estimator::agrees(const State& model, const State& sensed) const {
  if (encoders_.empty()) return model == sensed;
  for (std::size_t k = 0; k < kStateDim; ++k)
    if (std::abs(model[k] - sensed[k]) > kArmAgreement * (1.0 + std::abs(sensed[k]))) return false;
  return true;
}

State KalmanEstimator::start(const State& observed) {
  predicted_.resize(models_.size());
  for (std::size_t m = 0; m < models_.size(); ++m) predicted_[m] = rebuild(models_[m], observed, 0);
  misfit_.assign(models_.size(), 0.0);
  chosen_ = 0;
  lagged_ = predicted_[0];
  const auto& all = kPairs;
  for (std::size_t i = 0; i < all.size(); ++i)
    covariance_[i] = {sensor_variance_[all[i].pose], 0.0, sensor_variance_[all[i].velocity]};
  timeline_.start();
  return ahead();
}

void KalmanEstimator::predict() {
  // Every model stands at lagged_, its contacts warm where it was not corrected.
  const Action ran = timeline_.take_ran();
  for (std::size_t m = 0; m < models_.size(); ++m) {
    models_[m].step(ran);
    predicted_[m] = models_[m].state();
  }
  lagged_ = predicted_[chosen_];
  // The covariance moves as a pose and its velocity do over one step (the pose gains dt times
  // the velocity), plus the model's error.
  const auto& all = kPairs;
  for (std::size_t i = 0; i < all.size(); ++i) {
    Covariance& c = covariance_[i];
    c.pp += 2.0 * dt_ * c.pv + dt_ * dt_ * c.vv + process_variance_[all[i].pose];
    c.pv += dt_ * c.vv;
    c.vv += process_variance_[all[i].velocity];
  }
}

void KalmanEstimator::choose_model(const State& observed) {
  for (std::size_t m = 0; m < predicted_.size(); ++m) {
    double misfit = 0.0;
    for (std::size_t k = 0; k < kStateDim; ++k) {
      const double d = observed[k] - predicted_[m][k];
      misfit += 0.5 * d * d / (sensor_variance_[k] + process_variance_[k]);
    }
    misfit_[m] = kMisfitMemory * misfit_[m] + misfit;
  }
  const auto best = static_cast<std::size_t>(std::min_element(misfit_.begin(), misfit_.end()) - misfit_.begin());
  if (misfit_[best] < misfit_[chosen_] - kSwitchMargin) chosen_ = best;
  lagged_ = predicted_[chosen_];
}

void KalmanEstimator::correct(const State& observed) {
  if (models_.size() > 1) choose_model(observed);
  const auto& all = kPairs;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Pair& p = all[i];
    Covariance& c = covariance_[i];
    // The gain K = P (P + R)^-1 of the pair; with nothing uncertain and a perfect sensor, K = I.
    const double s00 = c.pp + sensor_variance_[p.pose], s11 = c.vv + sensor_variance_[p.velocity], s01 = c.pv;
    const double det = s00 * s11 - s01 * s01;
    double k00 = 1.0, k01 = 0.0, k10 = 0.0, k11 = 1.0;
    if (det > 0.0) {
      k00 = (c.pp * s11 - c.pv * s01) / det;
      k01 = (c.pv * s00 - c.pp * s01) / det;
      k10 = (c.pv * s11 - c.vv * s01) / det;
      k11 = (c.vv * s00 - c.pv * s01) / det;
    }
    const double yp = observed[p.pose] - lagged_[p.pose], yv = observed[p.velocity] - lagged_[p.velocity];
    lagged_[p.pose] += k00 * yp + k01 * yv;
    lagged_[p.velocity] += k10 * yp + k11 * yv;
    const Covariance before = c;
    c.pp = (1.0 - k00) * before.pp - k01 * before.pv;
    c.pv = 0.5 * (((1.0 - k00) * before.pv - k01 * before.vv) + ((1.0 - k11) * before.pv - k10 * before.pp));
    c.vv = (1.0 - k11) * before.vv - k10 * before.pv;
  }
  // Rebuilt only where corrected: a model the sensor agrees with keeps its contacts'
  // warm-starting, which a rebuild loses (the cup's velocity follows the dice it carries).
  // Moving the bodies of a running model instead, contacts kept, measured no better under noise.
  // Each model's prediction stays the state it stands at until the next step.
  // On an arm the rebuilt model holds the links its encoders read, and the cup where they hold it.
  for (std::size_t m = 0; m < predicted_.size(); ++m)
    if (!agrees(predicted_[m], lagged_)) predicted_[m] = rebuild(models_[m], lagged_, timeline_.lagged_step());
  if (!encoders_.empty()) lagged_ = predicted_[chosen_];  // the cup where the encoders' links hold it
}

State KalmanEstimator::update(const Action& chosen, const State& observed) {
  // When the observation moved on by a step, the lagged estimate is predicted through it first.
  if (timeline_.choose(chosen)) predict();
  correct(observed);
  return ahead();
}

State KalmanEstimator::ahead() {
  World& forecast = models_[chosen_];
  if (timeline_.empty()) {
    links_ = forecast.arm_links();
    return lagged_;
  }
  const WorldSnapshot at_lagged = forecast.snapshot();
  timeline_.run_on(forecast);
  const State landing = forecast.state();
  links_ = forecast.arm_links();
  forecast.restore(at_lagged);
  return landing;
}

std::unique_ptr<Estimator> make_estimator(const EstimatorConfig& config, const WorldConfig& model,
                                          const PerturbationDraw& draw, ActionKind actions) {
  bool noisy = false;
  for (double sigma : draw.observation_noise) noisy = noisy || sigma > 0.0;
  const bool sensed = noisy || draw.observation_delay > 0 || draw.action_delay > 0;
  if (config.kind == EstimatorKind::none || !sensed) return nullptr;
  // Without sensor noise there is nothing to weigh particles by: the delays alone are made up
  // exactly by the Kalman filter's forward simulation, which a particle filter would repeat.
  if (config.kind == EstimatorKind::particle && noisy) return std::make_unique<ParticleEstimator>(model, draw, config, actions);
  return std::make_unique<KalmanEstimator>(model, draw, config, actions);
}

}  // namespace dicestack
