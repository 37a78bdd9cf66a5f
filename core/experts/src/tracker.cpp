#include <dicestack/core/tracker.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

namespace si = state_index;

constexpr std::uint64_t kProbeStream = 0x70726f6265ULL;  // "probe"

double mean_dice_x(const State& s) {
  double x = 0.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) x += s[si::die(i)];
  return x / static_cast<double>(kDiceCount);
}

void check_path(const CupPath& p) {
  if (p.states.empty()) throw InputError("tracker: recording \"" + p.name + "\" has no steps");
  if (p.states.size() != p.actions.size())
    throw InputError("tracker: recording \"" + p.name + "\" has " + std::to_string(p.states.size()) + " states and " +
                     std::to_string(p.actions.size()) + " actions");
  for (std::size_t t = 0; t < p.states.size(); ++t) {
    require_finite(p.states[t], "tracker: recording \"" + p.name + "\" state " + std::to_string(t));
    require_finite(p.actions[t], "tracker: recording \"" + p.name + "\" action " + std::to_string(t));
  }
}

// One simulated episode of a follower: higher is better; only a realistic success scores above 0.
struct Trial {
  double score = -1e300;
  bool success = false;
};

Trial simulate(const PathFollower& follower, DiceEnv& sim, const EnvSnapshot& start, int hold_steps) {
  sim.restore(start);
  const bool clean = !sim.outcome().wall_contact;
  const int end = sim.t() + follower.length() + hold_steps;
  State s = sim.get_state();
  Trial trial;
  while (sim.t() < sim.config().episode.max_steps && sim.t() < end) {
    const StepResult r = sim.step(follower.act(s, sim.t()));
    s = r.observation;
    if (r.terminated) {
      trial.success = true;
      trial.score = 1.0 + 1.0 / (1.0 + r.info.t);  // the earlier success ranks higher
      return trial;
    }
    if (clean && r.info.outcome.wall_contact) break;
  }
  trial.score = -stack_shortfall(s, sim.config()) - (sim.outcome().wall_contact ? 1000.0 : 0.0);
  return trial;
}

// x in [-1, 1]^3 (clipped) to a warp inside the config's bounds.
PathWarp warp_from(const Eigen::VectorXd& x, const TrackerConfig& c) {
  auto clip = [](double v) { return std::clamp(v, -1.0, 1.0); };
  PathWarp w;
  w.time_scale = std::exp(clip(x[0]) * std::log1p(c.time_scale_range));
  w.offset = clip(x[1]) * c.offset_range;
  w.amplitude = 1.0 + clip(x[2]) * c.amplitude_range;
  return w;
}

}  // namespace

void validate(const TrackerConfig& c) {
  auto require = [](bool ok, const char* field, const char* rule, double got) {
    if (!ok)
      throw ConfigError("tracker config: field \"" + std::string(field) + "\" must be " + rule + ", got " +
                        std::to_string(got));
  };
  require(c.gain > 0.0 && c.gain < 1e6, "gain", "in (0, 1e6)", c.gain);
  require(c.probes >= 0 && c.probes <= 100000, "probes", "in [0, 100000]", c.probes);
  require(c.keep >= 0 && c.keep <= 1000000, "keep", "in [0, 1000000]", c.keep);
  require(c.optimise_paths >= 1 && c.optimise_paths <= 100000, "optimise_paths", "in [1, 100000]", c.optimise_paths);
  require(c.optimise_evaluations >= 1 && c.optimise_evaluations <= 100000, "optimise_evaluations", "in [1, 100000]",
          c.optimise_evaluations);
  require(c.time_scale_range >= 0.0 && c.time_scale_range < 1.0, "time_scale_range", "in [0, 1)", c.time_scale_range);
  require(c.offset_range >= 0.0 && c.offset_range <= 10.0, "offset_range", "in [0, 10]", c.offset_range);
  require(c.amplitude_range >= 0.0 && c.amplitude_range < 1.0, "amplitude_range", "in [0, 1)", c.amplitude_range);
  require(c.hold_steps >= 0 && c.hold_steps <= 100000, "hold_steps", "in [0, 100000]", c.hold_steps);
}

PathFollower::PathFollower(const CupPath& path, const PathWarp& warp, const State& start, int start_step, double gain)
    : path_(&path), warp_(warp), start_step_(start_step), gain_(gain) {
  centre_ = mean_dice_x(path.states.front());
  shift_ = mean_dice_x(start) - centre_ + warp.offset;
  length_ = static_cast<int>(std::ceil(static_cast<double>(path.states.size() - 1) / warp.time_scale));
}

Action PathFollower::act(const State& s, int step) const {
  const auto& states = path_->states;
  const auto& actions = path_->actions;
  const double u = std::max(0.0, static_cast<double>(step - start_step_) * warp_.time_scale);
  const std::size_t last = states.size() - 1;
  const bool held = static_cast<double>(last) <= u;
  const std::size_t i = held ? last : static_cast<std::size_t>(u);
  const std::size_t j = std::min(i + 1, last);
  const double f = held ? 0.0 : u - static_cast<double>(i);
  auto lerp = [f](double a, double b) { return a + f * (b - a); };
  constexpr std::size_t pose[3] = {si::kCupX, si::kCupY, si::kCupAngle};
  constexpr std::size_t velocity[3] = {si::kCupVx, si::kCupVy, si::kCupW};
  Action dv{};
  for (std::size_t k = 0; k < 3; ++k) {
    double p = lerp(states[i][pose[k]], states[j][pose[k]]);
    // The recorded velocity during the step: the state's, plus the step's action.
    double v = held ? 0.0
                    : warp_.time_scale *
                          lerp(states[i][velocity[k]] + actions[i][k], states[j][velocity[k]] + actions[j][k]);
    if (k == 0) {
      p = centre_ + shift_ + warp_.amplitude * (p - centre_);
      v *= warp_.amplitude;
    }
    double error = p - s[pose[k]];
    if (k == 2) error = std::remainder(error, 2.0 * std::numbers::pi);
    dv[k] = v + gain_ * error - s[velocity[k]];
  }
  return dv;
}

Recordings::Recordings(std::vector<CupPath> paths, const WorldConfig& world, const TrackerConfig& config,
                       std::uint64_t seed, int threads, Cluster& cluster)
    : paths_(std::move(paths)), config_(config), seed_(seed) {
  validate(config_);
  if (paths_.empty()) throw InputError("tracker: no recordings to follow");
  for (const auto& p : paths_) check_path(p);
  probe_successes_.assign(paths_.size(), 0);
  const auto probes = static_cast<std::size_t>(config_.probes);
  if (probes > 0) {
    // Every (path, probe start) pair is an item of its own, so the ranking is the same on any
    // number of threads or ranks.
    EnvPool envs(world, threads), sims(world, threads);
    const auto wins = distributed_map<int>(
        cluster, paths_.size() * probes, threads,
        [&](std::size_t item, int w) {
          const std::size_t path = item / probes, probe = item % probes;
          DiceEnv& env = envs.at(w);
          const State start = random_start_state(world, training_start_seed(derive_seed(seed_, kProbeStream), probe));
          env.reset_to(start, 0);
          const PathFollower follower(paths_[path], {}, start, 0, config_.gain);
          return simulate(follower, sims.at(w), env.snapshot(), config_.hold_steps).success ? 1 : 0;
        },
        [](const int& v) { return std::string(1, v ? '1' : '0'); }, [](std::string_view b) { return b == "1" ? 1 : 0; });
    for (std::size_t item = 0; item < wins.size(); ++item) probe_successes_[item / probes] += wins[item];
  }
  order_.resize(paths_.size());
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  std::stable_sort(order_.begin(), order_.end(),
                   [&](std::size_t a, std::size_t b) { return probe_successes_[a] > probe_successes_[b]; });
  if (config_.keep > 0 && static_cast<std::size_t>(config_.keep) < order_.size())
    order_.resize(static_cast<std::size_t>(config_.keep));
}

TrackerChoice choose_path(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, std::uint64_t seed) {
  const TrackerConfig& c = recordings.config();
  const EnvSnapshot start = env.snapshot();
  const State s = env.get_state();
  const int t = env.t();
  const auto& paths = recordings.paths();
  TrackerChoice choice;
  double best = -1e300;
  // Keeps the best failure so far; returns true on a success (which is then the choice).
  auto consider = [&](std::size_t p, const PathWarp& w) {
    const Trial trial = simulate(PathFollower(paths[p], w, s, t, c.gain), sim, start, c.hold_steps);
    ++choice.simulations;
    if (trial.score > best) {  // a success outscores every failure
      best = trial.score;
      choice.path = p;
      choice.warp = w;
      choice.success = trial.success;
    }
    return trial;
  };
  std::vector<std::pair<double, std::size_t>> near;  // (score, path) of the recordings as recorded
  for (const std::size_t p : recordings.order()) {
    const Trial trial = consider(p, {});
    if (trial.success) return choice;
    near.emplace_back(trial.score, p);
  }
  if (!c.optimise) return choice;
  std::stable_sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  near.resize(std::min(near.size(), static_cast<std::size_t>(c.optimise_paths)));
  for (const auto& [score, p] : near) {
    CmaesOptions o;
    o.sigma0 = 0.3;  // in units of the warp bounds
    o.max_evaluations = c.optimise_evaluations;
    o.seed = derive_seed(seed, p);
    Cmaes es(Eigen::VectorXd::Zero(3), o);
    while (!es.done()) {
      const Eigen::MatrixXd& x = es.ask();
      std::vector<double> values(static_cast<std::size_t>(x.rows()));
      for (Eigen::Index r = 0; r < x.rows(); ++r) {
        const Trial trial = consider(p, warp_from(x.row(r).transpose(), c));
        if (trial.success) return choice;
        values[static_cast<std::size_t>(r)] = -trial.score;
      }
      es.tell(values);
    }
  }
  return choice;
}

}  // namespace dicestack
