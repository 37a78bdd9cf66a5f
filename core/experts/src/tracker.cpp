#include <dicestack/core/tracker.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

#include "path_refine.hpp"
#include "path_trial.hpp"

namespace dicestack {
namespace tracker_detail {

namespace si = state_index;

Trial simulate(const PathFollower& follower, DiceEnv& sim, const EnvSnapshot& start, int hold_steps, ActionKind controller,
               const Action& noise, std::uint64_t noise_seed) {
  sim.restore(start);
  Rng rng(noise_seed);
  const auto& scale = sim.config().action.scale;
  const bool noisy = noise[0] > 0.0 || noise[1] > 0.0 || noise[2] > 0.0;
  const bool clean = !sim.outcome().wall_contact;
  const int end = sim.t() + follower.length() + hold_steps;
  State s = sim.get_state();
  Trial trial;
  while (sim.t() < sim.config().episode.max_steps && sim.t() < end) {
    Action a = follower.act(s, sim.t());
    if (noisy)
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] += noise[k] * scale[k] * rng.normal();
    const StepResult r = sim.step(controller == ActionKind::joint_torque ? told_in_torques(sim, a) : a);
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

CupPath folded(const CupPath& path) {
  CupPath out = path;
  for (std::size_t t = 0; t < out.states.size(); ++t) {
    out.states[t][si::kCupVx] += out.actions[t][0];
    out.states[t][si::kCupVy] += out.actions[t][1];
    out.states[t][si::kCupW] += out.actions[t][2];
    out.actions[t] = Action{};
  }
  return out;
}

}  // namespace tracker_detail

namespace {

using tracker_detail::simulate;
using tracker_detail::Trial;
namespace si = state_index;

constexpr std::uint64_t kProbeStream = 0x70726f6265ULL;  // "probe"
constexpr std::uint64_t kProbeNoiseStream = 0x70726f62654eULL;  // "probeN"
constexpr std::uint64_t kVariantNoiseStream = 0x76617269616eULL;  // "varian"

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

// `path` with its cup pose and velocity during each step (the state's, plus the step's action)
// smoothed by a Gaussian of std `sigma` steps, the actions folded into the velocities; the dice
// are left as recorded.
CupPath smoothed(const CupPath& path, double sigma) {
  const std::size_t n = path.states.size();
  const auto radius = static_cast<std::ptrdiff_t>(std::ceil(3.0 * sigma));
  constexpr std::size_t pose[3] = {si::kCupX, si::kCupY, si::kCupAngle};
  constexpr std::size_t velocity[3] = {si::kCupVx, si::kCupVy, si::kCupW};
  std::vector<std::array<double, 6>> raw(n);  // pose (angle unwrapped), velocity during the step
  for (std::size_t t = 0; t < n; ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      raw[t][k] = path.states[t][pose[k]];
      raw[t][3 + k] = path.states[t][velocity[k]] + path.actions[t][k];
    }
  for (std::size_t t = 1; t < n; ++t)
    raw[t][2] = raw[t - 1][2] + std::remainder(raw[t][2] - raw[t - 1][2], 2.0 * std::numbers::pi);
  CupPath out = path;
  for (std::size_t t = 0; t < n; ++t) {
    std::array<double, 6> sum{};
    double weight = 0.0;
    for (std::ptrdiff_t d = -radius; d <= radius; ++d) {
      const auto u = static_cast<std::ptrdiff_t>(t) + d;
      if (u < 0 || u >= static_cast<std::ptrdiff_t>(n)) continue;  // the window shrinks at the ends
      const double w = std::exp(-0.5 * static_cast<double>(d * d) / (sigma * sigma));
      for (std::size_t k = 0; k < 6; ++k) sum[k] += w * raw[static_cast<std::size_t>(u)][k];
      weight += w;
    }
    for (std::size_t k = 0; k < 3; ++k) {
      out.states[t][pose[k]] = sum[k] / weight;
      out.states[t][velocity[k]] = sum[3 + k] / weight;
      out.actions[t][k] = 0.0;
    }
  }
  return out;
}

// One noisy trial of a candidate, as a learner would play it: executed-action noise on every
// step and, with robust_warp, the whole path a little off (time scale, offset, amplitude drawn
// once). 1 if it still ends in a realistic success.
int robust_trial(const CupPath& path, const PathWarp& warp, const State& frame, int start_step, const TrackerConfig& c,
                 DiceEnv& sim, const EnvSnapshot& start, std::uint64_t seed) {
  PathWarp jittered = warp;
  if (c.robust_warp > 0.0) {
    Rng rng(derive_seed(seed, 1));
    jittered.time_scale *= std::exp(c.robust_warp * rng.normal());
    jittered.offset += c.robust_warp * rng.normal();
    jittered.amplitude *= 1.0 + c.robust_warp * rng.normal();
  }
  const PathFollower follower(path, jittered, frame, start_step, c.gain, c.keep_extremes);
  const Action noise{c.robust_noise, c.robust_noise, c.robust_noise};
  return simulate(follower, sim, start, c.hold_steps, c.controller, noise, seed).success ? 1 : 0;
}

// x in [-1, 1]^3 (clipped) to a warp of `base` inside the config's bounds.
PathWarp warp_from(const Eigen::VectorXd& x, const TrackerConfig& c, const PathWarp& base) {
  auto clip = [](double v) { return std::clamp(v, -1.0, 1.0); };
  PathWarp w = base;
  w.time_scale = base.time_scale * std::exp(clip(x[0]) * std::log1p(c.time_scale_range));
  w.offset = base.offset + clip(x[1]) * c.offset_range;
  w.amplitude = base.amplitude * (1.0 + clip(x[2]) * c.amplitude_range);
  return w;
}

// A path to try, moved by its base warp.
struct Candidate {
  std::size_t path = 0;
  PathWarp warp;
};

// One search's tally: the best failure so far (the choice until a success), the success with
// most noisy successes set aside under robust trials, and the episodes simulated.
class TrackerSearch {
 public:
  TrackerSearch(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, const State& frame, std::uint64_t seed)
      : c_(recordings.config()), start_(env.snapshot()), t_(env.t()), paths_(recordings.paths()), sim_(sim),
        frame_(frame), seed_(seed) {}

  // Simulates path p under warp w (moved into the frame) and keeps the best failure so far; a
  // success is then the choice. With robust trials, a success that fails some noisy trial is
  // kept aside and reported as a failure, so the search goes on.
  Trial consider(std::size_t p, const PathWarp& w) {
    const PathFollower follower(paths_[p], w, frame_, t_, c_.gain, c_.keep_extremes);
    Trial trial = simulate(follower, sim_, start_, c_.hold_steps, c_.controller);
    ++simulations_;
    if (trial.success && c_.robust > 0) {
      int wins = 0;
      for (int k = 0; k < c_.robust; ++k, ++simulations_) {
        const std::uint64_t trial_seed = derive_seed(seed_, static_cast<std::uint64_t>(simulations_));
        wins += robust_trial(paths_[p], w, frame_, t_, c_, sim_, start_, trial_seed);
      }
      if (wins > best_robust_) {
        best_robust_ = wins;
        robust_best_ = TrackerChoice{p, w, true, 0};
      }
      if (wins < c_.robust) trial.success = false;  // keep looking
      else trial.score = 2.0;
    }
    if (trial.score > best_) {  // a success outscores every failure
      best_ = trial.score;
      choice_.path = p;
      choice_.warp = w;
      choice_.success = trial.success;
    }
    choice_.simulations = simulations_;
    return trial;
  }

  // The choice as it stands: the success just found or the best failure.
  const TrackerChoice& choice() const { return choice_; }
  bool has_robust_best() const { return robust_best_.has_value(); }

  // The final choice: without a success, the success set aside if any, else the best failure.
  TrackerChoice finish() {
    if (!choice_.success && robust_best_) {
      choice_ = *robust_best_;
      choice_.simulations = simulations_;
    }
    return choice_;
  }

 private:
  const TrackerConfig& c_;
  const EnvSnapshot start_;
  const int t_;
  const std::vector<CupPath>& paths_;
  DiceEnv& sim_;
  const State& frame_;
  const std::uint64_t seed_;
  TrackerChoice choice_;
  double best_ = -1e300;
  int best_robust_ = -1;
  std::optional<TrackerChoice> robust_best_;  // the success with most noisy successes so far
  int simulations_ = 0;
};

using NearCandidates = std::vector<std::pair<double, std::size_t>>;  // (score, index into the candidates)

// The least narrowing of the swing that succeeds, in even steps, the closest paths at each step:
// alike for neighbouring starts, where CMA-ES's warps scatter. The search's answer once it is
// over (a success, or a robust success set aside), else nothing.
std::optional<TrackerChoice> search_shrunk(TrackerSearch& s, const TrackerConfig& c, const std::vector<Candidate>& candidates,
                                           const NearCandidates& near) {
  for (int step = 1; step <= c.shrink; ++step) {
    for (const auto& [score, k] : near) {
      PathWarp w = candidates[k].warp;
      w.amplitude *= 1.0 - c.amplitude_range * static_cast<double>(step) / static_cast<double>(c.shrink);
      if (s.consider(candidates[k].path, w).success) return s.choice();
    }
    if (s.has_robust_best()) return s.finish();
  }
  return std::nullopt;
}

// CMA-ES over the warps of the `near` candidates in turn, `evaluations` each; the first success,
// else the search's final choice.
TrackerChoice search_cmaes(TrackerSearch& s, const TrackerConfig& c, const std::vector<Candidate>& candidates,
                           const NearCandidates& near, int evaluations, std::uint64_t seed) {
  for (const auto& [score, k] : near) {
    const Candidate& base = candidates[k];
    CmaesOptions o;
    o.sigma0 = 0.3;  // in units of the warp bounds
    o.max_evaluations = evaluations;
    o.seed = derive_seed(seed, base.path);
    Cmaes es(Eigen::VectorXd::Zero(3), o);
    while (!es.done()) {
      const Eigen::MatrixXd& x = es.ask();
      std::vector<double> values(static_cast<std::size_t>(x.rows()));
      for (Eigen::Index r = 0; r < x.rows(); ++r) {
        const Trial trial = s.consider(base.path, warp_from(x.row(r).transpose(), c, base.warp));
        if (trial.success) return s.choice();
        values[static_cast<std::size_t>(r)] = -trial.score;
      }
      es.tell(values);
    }
  }
  return s.finish();
}

// Simulates `candidates` in turn from env's state (each moved into the frame of `frame`); the
// first success wins (with robust, the first whose noisy trials all succeed too, else the
// success with most). Failing that, the `optimise_paths` closest narrowed in shrink even
// steps, then CMA-ES over their warps, `evaluations` each; failing all, the closest.
TrackerChoice search(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, const State& frame,
                     const std::vector<Candidate>& candidates, int evaluations, std::uint64_t seed) {
  const TrackerConfig& c = recordings.config();
  TrackerSearch s(recordings, env, sim, frame, seed);
  NearCandidates near;  // as given
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const Trial trial = s.consider(candidates[k].path, candidates[k].warp);
    if (trial.success) return s.choice();
    near.emplace_back(trial.score, k);
  }
  if (!c.optimise || s.has_robust_best()) return s.finish();
  std::stable_sort(near.begin(), near.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  near.resize(std::min(near.size(), static_cast<std::size_t>(c.optimise_paths)));
  if (auto done = search_shrunk(s, c, candidates, near)) return *done;
  return search_cmaes(s, c, candidates, near, evaluations, seed);
}

// How far recorded state `r` (its x moved by `shift`) is from `s`, for joining a path there: the
// cup's pose and velocity, and the dice relative to the cup. Metres, with angles at 0.1 m/rad and
// velocities over 0.1 s (the feedback's time constant).
double join_distance(const State& r, double shift, const State& s) {
  double d = 0.3 * std::abs(r[si::kCupX] + shift - s[si::kCupX]) + std::abs(r[si::kCupY] - s[si::kCupY]) +
             0.1 * std::abs(std::remainder(r[si::kCupAngle] - s[si::kCupAngle], 2.0 * std::numbers::pi)) +
             0.1 * (std::abs(r[si::kCupVx] - s[si::kCupVx]) + std::abs(r[si::kCupVy] - s[si::kCupVy])) +
             0.01 * std::abs(r[si::kCupW] - s[si::kCupW]);
  for (std::size_t i = 0; i < kDiceCount; ++i)
    for (std::size_t k = 0; k < 2; ++k)
      d += std::abs((r[si::die(i) + k] - r[k]) - (s[si::die(i) + k] - s[k])) / static_cast<double>(kDiceCount);
  return d;
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
  require(c.paths >= 0 && c.paths <= 1000000, "paths", "in [0, 1000000]", c.paths);
  require(c.optimise_paths >= 1 && c.optimise_paths <= 100000, "optimise_paths", "in [1, 100000]", c.optimise_paths);
  require(c.optimise_evaluations >= 1 && c.optimise_evaluations <= 100000, "optimise_evaluations", "in [1, 100000]",
          c.optimise_evaluations);
  require(c.time_scale_range >= 0.0 && c.time_scale_range < 1.0, "time_scale_range", "in [0, 1)", c.time_scale_range);
  require(c.offset_range >= 0.0 && c.offset_range <= 10.0, "offset_range", "in [0, 10]", c.offset_range);
  require(c.amplitude_range >= 0.0 && c.amplitude_range < 1.0, "amplitude_range", "in [0, 1)", c.amplitude_range);
  require(c.hold_steps >= 0 && c.hold_steps <= 100000, "hold_steps", "in [0, 100000]", c.hold_steps);
  require(c.refine >= 0 && c.refine <= 10000, "refine", "in [0, 10000]", c.refine);
  require(c.refine_probes >= 1 && c.refine_probes <= 100000, "refine_probes", "in [1, 100000]", c.refine_probes);
  require(c.refine_restarts >= 1 && c.refine_restarts <= 100, "refine_restarts", "in [1, 100]", c.refine_restarts);
  require(c.refine_enough >= 0.0 && c.refine_enough <= 1.0, "refine_enough", "in [0, 1]", c.refine_enough);
  require(c.refine_knots >= 1 && c.refine_knots <= 100, "refine_knots", "in [1, 100]", c.refine_knots);
  for (std::size_t k = 0; k < 3; ++k)
    require(c.refine_range[k] >= 0.0 && c.refine_range[k] <= 10.0, "refine_range", "in [0, 10] per axis", c.refine_range[k]);
  require(c.refine_range[3] >= 0.0 && c.refine_range[3] <= 1.0, "refine_timing", "in [0, 1]", c.refine_range[3]);
  for (const double n : c.refine_noise) require(n >= 0.0 && n <= 10.0, "refine_noise", "in [0, 10] per axis", n);
  require(c.smooth >= 0.0 && c.smooth <= 1000.0, "smooth", "in [0, 1000]", c.smooth);
  require(c.rescue >= 0 && c.rescue <= 100000, "rescue", "in [0, 100000]",
          c.rescue);
  require(c.robust >= 0 && c.robust <= 1000, "robust", "in [0, 1000]", c.robust);
  require(c.robust_noise >= 0.0 && c.robust_noise <= 10.0, "robust_noise", "in [0, 10]", c.robust_noise);
  require(c.robust_warp >= 0.0 && c.robust_warp <= 1.0, "robust_warp", "in [0, 1]", c.robust_warp);
  require(c.shrink >= 0 && c.shrink <= 100, "shrink", "in [0, 100]", c.shrink);
  require(c.rescue_evaluations >= 1 && c.rescue_evaluations <= 100000, "rescue_evaluations", "in [1, 100000]",
          c.rescue_evaluations);
  require(c.variants.size() <= 100, "variants", "at most 100 widths long", static_cast<double>(c.variants.size()));
  for (const double w : c.variants) require(w >= 0.0 && w <= 1000.0, "variants", "widths in [0, 1000]", w);
  require(c.variant_recordings >= 1 && c.variant_recordings <= 1000000, "variant_recordings", "in [1, 1000000]",
          c.variant_recordings);
  require(c.finalists >= 1 && c.finalists <= 100000, "finalists", "in [1, 100000]", c.finalists);
  require(c.finalist_probes >= 0 && c.finalist_probes <= 100000, "finalist_probes", "in [0, 100000]", c.finalist_probes);
}

PathFollower::PathFollower(const CupPath& path, const PathWarp& warp, const State& start, int start_step, double gain,
                           bool keep_extremes)
    : path_(&path), warp_(warp), start_step_(start_step), gain_(gain) {
  centre_ = mean_dice_x(path.states.front());
  shift_ = mean_dice_x(start) - centre_ + warp.offset;
  if (keep_extremes) {
    // The moved swing reaches no further left or right than the recording did from its own start.
    double lo = centre_, hi = centre_;
    for (const State& s : path.states) lo = std::min(lo, s[si::kCupX]), hi = std::max(hi, s[si::kCupX]);
    double room = 1.0;
    if (hi - centre_ > 1e-9) room = std::min(room, (hi - centre_ - shift_) / (warp_.amplitude * (hi - centre_)));
    if (centre_ - lo > 1e-9) room = std::min(room, (centre_ + shift_ - lo) / (warp_.amplitude * (centre_ - lo)));
    warp_.amplitude *= std::max(room, 0.5);
  }
  length_ = static_cast<int>(
      std::ceil(std::max(0.0, static_cast<double>(path.states.size() - 1) - warp.phase) / warp.time_scale));
}

double PathFollower::phase(int step) const {
  return warp_.phase + std::max(0.0, static_cast<double>(step - start_step_) * warp_.time_scale);
}

Action PathFollower::act(const State& s, int step) const {
  const auto& states = path_->states;
  const auto& actions = path_->actions;
  const double u = phase(step);
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
                       std::uint64_t seed, int threads, Cluster& cluster, const TrackerProgress& progress)
    : paths_(std::move(paths)), config_(config), seed_(seed) {
  validate(config_);
  if (paths_.empty()) throw InputError("tracker: no recordings to follow");
  for (const auto& p : paths_) check_path(p);
  if (progress) progress("ranking the paths", 0, 1);
  const std::vector<CupPath> recorded = config_.variants.empty() ? std::vector<CupPath>{} : paths_;
  if (config_.smooth > 0.0)
    for (auto& p : paths_) p = smoothed(p, config_.smooth);
  const int per_probe = 1 + config_.robust;
  probe_successes_ = probe_scores(world, threads, cluster, 0, paths_.size(), 0, config_.probes, false);
  probe_trials_.assign(paths_.size(), config_.probes * per_probe);
  std::vector<std::size_t> finalists;
  if (!recorded.empty() && config_.probes > 0) {
    // The best-ranked recordings, each also smoothed by every other width, scored alike.
    const std::size_t n = recorded.size();
    for (const std::size_t r : ranked(std::min(n, static_cast<std::size_t>(config_.variant_recordings))))
      for (const double width : config_.variants) {
        if (width == config_.smooth) continue;
        CupPath v = width > 0.0 ? smoothed(recorded[r], width) : recorded[r];
        std::ostringstream name;
        name << recorded[r].name << " (smoothed " << width << ")";
        v.name = name.str();
        paths_.push_back(std::move(v));
      }
    const auto more = probe_scores(world, threads, cluster, n, paths_.size(), 0, config_.probes, true);
    probe_successes_.insert(probe_successes_.end(), more.begin(), more.end());
    probe_trials_.resize(paths_.size(), config_.probes * per_probe);
    // The best of many scores is lucky: the finalists are scored again from fresh starts.
    finalists = ranked(std::min(paths_.size(), static_cast<std::size_t>(config_.finalists)));
    for (const std::size_t f : finalists) {
      probe_successes_[f] += probe_scores(world, threads, cluster, f, f + 1, config_.probes, config_.finalist_probes, true)[0];
      probe_trials_[f] += config_.finalist_probes * per_probe;
    }
  }
  // Finalists first, by their score over all their trials; then the rest, most successes first.
  order_ = ranked(paths_.size());
  if (!finalists.empty()) {
    std::stable_sort(finalists.begin(), finalists.end(), [&](std::size_t a, std::size_t b) {
      return static_cast<double>(probe_successes_[a]) / probe_trials_[a] > static_cast<double>(probe_successes_[b]) / probe_trials_[b];
    });
    std::erase_if(order_, [&](std::size_t p) { return std::find(finalists.begin(), finalists.end(), p) != finalists.end(); });
    order_.insert(order_.begin(), finalists.begin(), finalists.end());
  }
  if (progress) progress("ranking the paths", 1, 1);
  if (config_.refine > 0) refine_leaders(world, threads, cluster, progress);
  if (config_.paths > 0 && static_cast<std::size_t>(config_.paths) < order_.size())
    order_.resize(static_cast<std::size_t>(config_.paths));
}

void Recordings::refine_leaders(const WorldConfig& world, int threads, Cluster& cluster, const TrackerProgress& progress) {
  // Restart i refines the order's i-th path (wrapping) from a seed of its own: one refinement's
  // answer varies with its seed and its path as much as between recordings. Each is validated
  // on the same fresh starts as the leader as followed.
  const auto validated = [&](const CupPath& p) {
    return tracker_detail::validation_successes({p}, world, config_, seed_, threads, cluster).front();
  };
  const int leader = validated(paths_[order_.front()]);
  const int trials = tracker_detail::validation_trials(config_);
  std::vector<CupPath> refined;
  std::vector<int> successes;
  for (int i = 0; i < config_.refine_restarts; ++i) {
    const std::size_t from = order_[static_cast<std::size_t>(i) % order_.size()];
    const std::uint64_t seed = i == 0 ? seed_ : derive_seed(seed_, static_cast<std::uint64_t>(i));
    const std::string stage = "refining path " + std::to_string(i + 1) + " of " + std::to_string(config_.refine_restarts);
    const auto generation_done = [&](int done, int total) {
      if (progress) progress(stage, done, total);
    };
    refined.push_back(tracker_detail::refine_path(paths_[from], world, config_, seed, threads, cluster, generation_done));
    if (i > 0) refined.back().name = paths_[from].name + " (refined, restart " + std::to_string(i) + ")";
    successes.push_back(validated(refined.back()));
    if (successes.back() >= config_.refine_enough * trials) break;
  }
  // The best refined path (the first of equals) leads if it beats the leader; the others follow
  // every path of the order.
  const auto best = static_cast<std::size_t>(std::max_element(successes.begin(), successes.end()) - successes.begin());
  for (std::size_t i = 0; i < refined.size(); ++i) {
    paths_.push_back(std::move(refined[i]));
    probe_successes_.push_back(successes[i]);
    probe_trials_.push_back(trials);
    const std::size_t added = paths_.size() - 1;
    if (i == best && successes[i] > leader) order_.insert(order_.begin(), added);
    else order_.push_back(added);
  }
}

std::vector<std::size_t> Recordings::ranked(std::size_t count) const {
  std::vector<std::size_t> order(probe_successes_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return probe_successes_[a] > probe_successes_[b]; });
  order.resize(std::min(count, order.size()));
  return order;
}

std::vector<int> Recordings::probe_scores(const WorldConfig& world, int threads, Cluster& cluster, std::size_t from,
                                          std::size_t to, int first_probe, int probes, bool variants) const {
  std::vector<int> score(to - from, 0);
  if (probes <= 0 || to <= from) return score;
  // Every (path, probe start) pair is an item of its own, so the ranking is the same on any
  // number of threads or ranks.
  const auto per = static_cast<std::size_t>(probes);
  EnvPool envs(world, threads), sims(world, threads);
  const auto wins = distributed_map<int>(
      cluster, (to - from) * per, threads,
      [&](std::size_t item, int w) {
        const std::size_t path = from + item / per, probe = static_cast<std::size_t>(first_probe) + item % per;
        DiceEnv& env = envs.at(w);
        const State start = random_start_state(world, training_start_seed(derive_seed(seed_, kProbeStream), probe));
        env.reset_to(start, 0);
        const PathFollower follower(paths_[path], {}, start, 0, config_.gain, config_.keep_extremes);
        const EnvSnapshot snap = env.snapshot();
        // A probe scores 1 for a success as simulated, plus 1 per noisy trial that succeeds too.
        if (!simulate(follower, sims.at(w), snap, config_.hold_steps, config_.controller).success) return 0;
        // The recordings' own noise seeds are those of the first ranking, which variants left as it was.
        const std::uint64_t noise = variants ? derive_seed(derive_seed(seed_, kVariantNoiseStream), path * 1000003 + probe)
                                             : derive_seed(seed_, kProbeNoiseStream);
        const std::size_t key = variants ? 0 : item;
        int won = 1;
        for (int k = 0; k < config_.robust; ++k)
          won += robust_trial(paths_[path], {}, start, 0, config_, sims.at(w), snap,
                              derive_seed(noise, key * 1000 + static_cast<std::size_t>(k)));
        return won;
      },
      [](const int& v) { return std::to_string(v); }, [](std::string_view b) { return std::stoi(std::string(b)); });
  for (std::size_t item = 0; item < wins.size(); ++item) score[item / per] += wins[item];
  return score;
}

TrackerChoice choose_path(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, std::uint64_t seed) {
  std::vector<Candidate> candidates;
  for (const std::size_t p : recordings.order()) candidates.push_back({p, {}});
  return search(recordings, env, sim, env.get_state(), candidates, recordings.config().optimise_evaluations, seed);
}

bool still_succeeds(const PathFollower& follower, const DiceEnv& env, DiceEnv& sim, int hold_steps, ActionKind controller) {
  return simulate(follower, sim, env.snapshot(), hold_steps, controller).success;
}

TrackerChoice rescue_path(const Recordings& recordings, const DiceEnv& env, DiceEnv& sim, const State& frame,
                          const TrackerChoice& current, double current_phase, std::uint64_t seed) {
  const State s = env.get_state();
  const double frame_x = mean_dice_x(frame);
  std::vector<Candidate> candidates;
  PathWarp rest = current.warp;
  rest.phase = current_phase;
  candidates.push_back({current.path, rest});
  for (const std::size_t p : recordings.order()) {
    if (p == current.path) continue;
    const CupPath& path = recordings.paths()[p];
    const double shift = frame_x - mean_dice_x(path.states.front());
    std::size_t join = 0;
    double nearest = 1e300;
    for (std::size_t i = 0; i + 1 < path.states.size(); ++i) {
      const double d = join_distance(path.states[i], shift, s);
      if (d < nearest) nearest = d, join = i;
    }
    PathWarp w;
    w.phase = static_cast<double>(join);
    w.offset = s[si::kCupX] - (path.states[join][si::kCupX] + shift);  // meet the cup where it is
    candidates.push_back({p, w});
  }
  const TrackerConfig& c = recordings.config();
  return search(recordings, env, sim, frame, candidates, c.rescue_evaluations, derive_seed(seed, env.t()));
}

}  // namespace dicestack
