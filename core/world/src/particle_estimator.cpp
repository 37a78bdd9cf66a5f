#include <dicestack/core/estimator.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

// The particles' seed stream within the episode's noise seed.
constexpr std::uint64_t kParticleStream = 0x7061727469636c65ULL;  // "particle"

}  // namespace

ParticleEstimator::ParticleEstimator(const WorldConfig& model, const PerturbationDraw& draw, const EstimatorConfig& config,
                                     ActionKind actions)
    : timeline_(draw.action_delay, draw.observation_delay, actions), seed_(derive_seed(draw.noise_seed, kParticleStream)),
      scratch_(model) {
  if (config.particles < 1 || config.particles > kMaxParticles)
    throw ConfigError("particle filter: takes 1 to " + std::to_string(kMaxParticles) + " particles, got " +
                      std::to_string(config.particles));
  for (std::size_t k = 0; k < kStateDim; ++k) {
    sensor_sigma_[k] = draw.observation_noise[k];
    process_sigma_[k] = config.particle_model_error * model_error_of(k);
  }
  worlds_.reserve(static_cast<std::size_t>(config.particles));
  for (int i = 0; i < config.particles; ++i) worlds_.emplace_back(model);
  states_.resize(worlds_.size());
  weights_.assign(worlds_.size(), 1.0 / static_cast<double>(worlds_.size()));
}

State ParticleEstimator::start(const State& observed) {
  rng_ = Rng(seed_);
  // The prior: the observation (the first particle) and draws around it by the sensor's noise.
  for (std::size_t i = 0; i < worlds_.size(); ++i) {
    State s = observed;
    if (i > 0)
      for (std::size_t k = 0; k < kStateDim; ++k) s[k] += sensor_sigma_[k] * rng_.normal();
    worlds_[i].set_state(s);
    states_[i] = worlds_[i].state();
  }
  std::fill(weights_.begin(), weights_.end(), 1.0 / static_cast<double>(worlds_.size()));
  predicted_ = false;
  timeline_.start();
  return ahead();
}

void ParticleEstimator::predict() {
  const Action ran = timeline_.take_ran();
  for (std::size_t i = 0; i < worlds_.size(); ++i) {
    worlds_[i].step(ran);
    states_[i] = worlds_[i].state();
  }
  predicted_ = true;
}

void ParticleEstimator::weigh(const State& observed) {
  // Each particle moves from its prediction x towards the observation z, number by number, as
  // the optimal proposal does for Gaussian model error q and sensor noise r: drawn around
  // (r x + q z) / (q + r) with variance q r / (q + r), weighted by how likely z was from x,
  // N(z; x, q + r). A number the sensor gives exactly (r = 0) is set to z, weighted by N(z; x, q).
  // Without a prediction since the last observation only the weights change.
  std::vector<double> log_w(worlds_.size(), 0.0);
  for (std::size_t i = 0; i < worlds_.size(); ++i) {
    bool moved = predicted_;
    for (std::size_t k = 0; k < kStateDim; ++k) {
      const double q = predicted_ ? process_sigma_[k] * process_sigma_[k] : 0.0, r = sensor_sigma_[k] * sensor_sigma_[k];
      const double d = observed[k] - states_[i][k];
      if (q + r > 0.0) log_w[i] += -0.5 * d * d / (q + r);
      if (r <= 0.0) {
        moved = moved || d != 0.0;
        states_[i][k] = observed[k];
      } else if (q > 0.0) {
        states_[i][k] += q / (q + r) * d + std::sqrt(q * r / (q + r)) * rng_.normal();
      }
    }
    if (moved) worlds_[i].set_state(states_[i]);
  }
  predicted_ = false;
  // New weights from the old by log-sum-exp; a particle whose likelihood is not finite (a
  // simulation thrown apart) weighs nothing, and if none is finite the weights start afresh.
  double top = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < worlds_.size(); ++i) {
    if (!std::isfinite(log_w[i]) || weights_[i] <= 0.0) log_w[i] = -std::numeric_limits<double>::infinity();
    else log_w[i] += std::log(weights_[i]);
    top = std::max(top, log_w[i]);
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < worlds_.size(); ++i) sum += weights_[i] = std::isfinite(top) ? std::exp(log_w[i] - top) : 1.0;
  for (double& w : weights_) w /= sum;
  resample_if_starved();
}

void ParticleEstimator::resample_if_starved() {
  // Systematic resampling when the effective count falls below half.
  double squares = 0.0;
  for (double w : weights_) squares += w * w;
  if (1.0 / squares >= 0.5 * static_cast<double>(worlds_.size())) return;
  const std::size_t n = worlds_.size();
  std::vector<std::size_t> pick(n);
  const double step = 1.0 / static_cast<double>(n);
  double u = rng_.uniform() * step, cumulative = weights_[0];
  for (std::size_t j = 0, i = 0; j < n; ++j, u += step) {
    while (u > cumulative && i + 1 < n) cumulative += weights_[++i];
    pick[j] = i;
  }
  std::vector<State> chosen(n);
  for (std::size_t j = 0; j < n; ++j) chosen[j] = states_[pick[j]];
  for (std::size_t j = 0; j < n; ++j) {
    states_[j] = chosen[j];
    worlds_[j].set_state(states_[j]);
  }
  std::fill(weights_.begin(), weights_.end(), step);
}

State ParticleEstimator::mean() const {
  State m{};
  for (std::size_t i = 0; i < worlds_.size(); ++i)
    for (std::size_t k = 0; k < kStateDim; ++k) m[k] += weights_[i] * states_[i][k];
  return m;
}

State ParticleEstimator::update(const Action& chosen, const State& observed) {
  if (timeline_.choose(chosen)) predict();
  weigh(observed);
  return ahead();
}

State ParticleEstimator::ahead() {
  const State now = mean();
  if (timeline_.empty()) return now;
  scratch_.set_state(now);
  timeline_.run_on(scratch_);
  return scratch_.state();
}

}  // namespace dicestack
