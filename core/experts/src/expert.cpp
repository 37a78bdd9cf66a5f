#include <dicestack/core/expert.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/rng.hpp>

#include "swing_plan.hpp"

namespace dicestack {
namespace {

namespace si = state_index;
using detail::SwingPlan;

// The simulator an expert plans in: a world like `env`'s, made again when an episode brings
// another (a perturbed world), so a plan never depends on which episode came first.
DiceEnv& planning_sim(std::optional<DiceEnv>& sim, const DiceEnv& env) {
  if (!sim || sim->config() != env.config()) sim.emplace(env.config());
  return *sim;
}

void require_config(bool ok, const char* field, const std::string& rule, double got) {
  if (!ok) throw ConfigError("expert config: field \"" + std::string(field) + "\" must be " + rule + ", got " +
                             std::to_string(got));
}

void validate(const ExpertConfig& c) {
  const SwingParams& p = c.swing;
  require_config(p.first_direction == 1.0 || p.first_direction == -1.0, "swing.first_direction", "+1 or -1",
                 p.first_direction);
  require_config(p.amplitude >= 0.0, "swing.amplitude", ">= 0", p.amplitude);
  require_config(p.half_period >= 1.0, "swing.half_period", ">= 1", p.half_period);
  require_config(p.half_swings >= 0 && p.half_swings <= 50, "swing.half_swings", "in [0, 50]", p.half_swings);
  require_config(p.pivot_depth > 0.0, "swing.pivot_depth", "> 0", p.pivot_depth);
  require_config(p.clearance >= 0.0, "swing.clearance", ">= 0", p.clearance);
  require_config(p.stop_speed >= 0.0, "swing.stop_speed", ">= 0", p.stop_speed);
  require_config(p.final_duration >= 1.0, "swing.final_duration", ">= 1", p.final_duration);
  require_config(p.tilt_time > 0.0, "swing.tilt_time", "> 0", p.tilt_time);
  require_config(c.gain > 0.0, "gain", "> 0", c.gain);
  require_config(c.wall_margin >= 0.0, "wall_margin", ">= 0", c.wall_margin);
  require_config(c.search_budget >= 1, "search_budget", ">= 1", c.search_budget);
  require_config(c.search_spread >= 0.0, "search_spread", ">= 0", c.search_spread);
  require_config(c.replan_budget >= 1, "replan_budget", ">= 1", c.replan_budget);
  require_config(c.replan_interval >= 1, "replan_interval", ">= 1", c.replan_interval);
  require_config(c.robust_trials >= 0 && c.robust_trials <= 1000, "robust_trials", "in [0, 1000]", c.robust_trials);
  require_config(c.robust_noise >= 0.0 && c.robust_noise <= 10.0, "robust_noise", "in [0, 10]", c.robust_noise);
}

bool same_state(const State& a, const State& b) { return std::memcmp(a.data(), b.data(), sizeof(State)) == 0; }

// Distance from a quarter turn.
double off_square(double angle) {
  const double q = std::numbers::pi / 2.0;
  return std::abs(angle - q * std::round(angle / q));
}

// How far the dice are from a column at rest on the table (0 for a perfect one), m-ish.
double column_error(const State& s, const WorldConfig& c) {
  std::array<std::size_t, kDiceCount> order{0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return s[si::die(a) + 1] < s[si::die(b) + 1]; });
  const double bottom = table_height(c.walls) + c.dice.half_size, side = 2.0 * c.dice.half_size;
  double err = 0.0;
  for (std::size_t k = 0; k < kDiceCount; ++k) {
    const std::size_t d = si::die(order[k]);
    err += std::abs(s[d] - s[si::die(order[0])]) + std::abs(s[d + 1] - bottom - side * static_cast<double>(k)) +
           0.2 * off_square(s[d + 2]) + 0.1 * std::hypot(s[d + 3], s[d + 4]);
  }
  return err;
}

// Follows one swing plan with fixed parameters; re-anchors it whenever the episode's step count
// does not continue the one it saw last (a new episode, or a state from elsewhere).
class ScriptedExpert final : public Expert {
 public:
  explicit ScriptedExpert(const ExpertConfig& config) : config_(config) {}
  std::string name() const override { return "scripted"; }

 private:
  void do_reset(std::uint64_t) override { last_step_ = -2; }
  Action do_act(const DiceEnv& env, const State& sensed) override {
    const int t = env.t();
    if (!plan_.valid() || t != last_step_ + 1) plan_ = SwingPlan(config_.swing, config_, env.config(), env.get_state(), t);
    last_step_ = t;
    return plan_.act(sensed, t);
  }

  ExpertConfig config_;
  SwingPlan plan_;
  int last_step_ = -2;
};

// Sees an episode's states, one per act(), and tells when a new attempt begins at the current
// one (attempt_start), judged in the default world as the "+retry" feature maps judge it.
class AttemptWatch {
 public:
  void clear() { seen_.clear(); }
  bool begins(const DiceEnv& env) {
    static const WorldConfig judged{};
    const auto t = static_cast<std::size_t>(env.t());
    if (t + 1 == seen_.size()) seen_.pop_back();  // asked again at the same step
    else if (t < seen_.size()) seen_.clear();     // a new episode without a reset
    seen_.push_back(env.get_state());
    return t > 0 && failed_at_rest(seen_.back(), judged) && attempt_start(seen_, judged) == seen_.size() - 1;
  }

 private:
  std::vector<State> seen_;
};

// Searches swing plans by simulating each from an exact snapshot of the environment to the end
// of the episode, and follows the first that succeeds (else the best). While the world stays on
// the predicted trajectory nothing is simulated again; any other state (a DAgger query, noise)
// first re-checks the current plan, then searches the nominal plan and seeded perturbations.
class MpcExpert final : public Expert {
 public:
  explicit MpcExpert(const ExpertConfig& config) : config_(config) {}
  std::string name() const override { return "mpc"; }

 private:
  struct Trial {
    double score = -1e18;
    std::vector<State> states;
  };

  void do_reset(std::uint64_t seed) override {
    seed_ = seed;
    plan_ = SwingPlan();
    predicted_.clear();
    last_replan_ = 0;
    attempts_.clear();
  }

  Action do_act(const DiceEnv& env, const State& sensed) override {
    if (config_.retry && attempts_.begins(env)) plan_ = SwingPlan();  // searched afresh below
    const int t = env.t();
    const State s = env.get_state();
    const int index = t - predicted_from_;
    const bool on_track = plan_.valid() && index >= 0 && index < static_cast<int>(predicted_.size()) &&
                          same_state(predicted_[static_cast<std::size_t>(index)], s);
    const bool fresh =
        !plan_.valid() || (config_.replan && (t < last_replan_ || t - last_replan_ >= config_.replan_interval));
    if (!on_track && fresh) replan(env);
    return plan_.act(sensed, t);
  }

  // `noise` > 0: executed-action noise of that std (x action.scale), drawn from `noise_seed`.
  Trial simulate(SwingPlan plan, const EnvSnapshot& start, double noise = 0.0, std::uint64_t noise_seed = 0) {
    sim_->restore(start);
    Trial trial;
    trial.states.push_back(sim_->get_state());
    const bool clean = !sim_->outcome().wall_contact;
    StepResult r;
    r.observation = sim_->get_state();
    Rng rng(noise_seed);
    const auto& scale = sim_->config().action.scale;
    while (sim_->t() < sim_->config().episode.max_steps) {
      Action a = plan.act(r.observation, sim_->t());
      if (noise > 0.0)
        for (std::size_t k = 0; k < kActionDim; ++k) a[k] += noise * scale[k] * rng.normal();
      r = sim_->step(a);
      trial.states.push_back(r.observation);
      if (r.terminated) {
        trial.score = 1000.0 - static_cast<double>(r.info.t);
        return trial;
      }
      if (clean && r.info.outcome.wall_contact) break;
      if (plan.finished(sim_->t())) break;
    }
    trial.score = -column_error(r.observation, sim_->config()) - (sim_->outcome().wall_contact ? 10.0 : 0.0);
    return trial;
  }

  // A plan near `n`; with `shorter`, sometimes one with fewer swings (a state met mid-episode
  // may need fewer, and the time limit may allow no more).
  SwingParams perturbed(const SwingParams& n, Rng& rng, bool shorter) const {
    const double f = config_.search_spread;
    auto jitter = [&](double x, double lo, double hi) { return std::clamp(x + f * (hi - lo) * rng.normal(), lo, hi); };
    SwingParams p = n;
    if (rng.uniform() < 0.25) p.first_direction = -p.first_direction;
    if (shorter && rng.uniform() < 0.5) p.half_swings = static_cast<int>(rng.below(static_cast<std::uint64_t>(n.half_swings) + 1));
    else p.half_swings = std::clamp(n.half_swings + static_cast<int>(std::lround(jitter(0.0, -6.0, 6.0))), 0, 7);
    p.amplitude = jitter(n.amplitude, 0.5, 2.8);
    p.half_period = jitter(n.half_period, 8.0, 32.0);
    p.pivot_depth = jitter(n.pivot_depth, 1.5, 6.0);
    p.clearance = jitter(n.clearance, 0.0, 0.15);
    p.centre_offset = jitter(n.centre_offset, -0.3, 0.3);
    p.stop_offset = jitter(n.stop_offset, -0.6, 0.6);
    p.stop_speed = jitter(n.stop_speed, 0.0, 16.0);
    p.final_duration = jitter(n.final_duration, 6.0, 30.0);
    p.end_tilt = jitter(n.end_tilt, -0.4, 0.4);
    p.tilt_time = jitter(n.tilt_time, 1.0, 15.0);
    return p;
  }

  void replan(const DiceEnv& env) {
    planning_sim(sim_, env);
    const EnvSnapshot start = env.snapshot();
    const State s = env.get_state();
    const int t = env.t();
    Rng rng(derive_seed(seed_, static_cast<std::uint64_t>(t)));
    const std::uint64_t robust_seed = derive_seed(derive_seed(seed_, static_cast<std::uint64_t>(t)), 0x726f62757374ULL);
    std::optional<SwingPlan> best_plan, robust_plan;
    Trial best, robust;
    int robust_wins = -1, trials = 0;
    // A success ends the search; with robust_trials, only one whose noisy trials all succeed too
    // (the success with most is kept in case none does).
    auto consider = [&](const SwingPlan& plan) {
      Trial trial = simulate(plan, start);
      if (trial.score >= 0.0 && config_.robust_trials > 0) {
        int wins = 0;
        for (int k = 0; k < config_.robust_trials; ++k)
          wins += simulate(plan, start, config_.robust_noise, derive_seed(robust_seed, static_cast<std::uint64_t>(++trials)))
                      .score >= 0.0;
        if (wins > robust_wins) robust_wins = wins, robust_plan = plan, robust = trial;
        if (wins < config_.robust_trials) return false;
      }
      if (!best_plan || trial.score > best.score) {
        best = std::move(trial);
        best_plan = plan;
      }
      return best.score >= 0.0;
    };
    bool done = false;
    const bool same_episode = plan_.valid() && t > plan_.anchor_step();
    int budget = same_episode ? config_.replan_budget : config_.search_budget;
    if (same_episode) {
      // Same episode: first the plan in force, then plans in the same phase (same anchor, nearby
      // parameters), so that a replan does not start the swinging over.
      const SwingPlan current = plan_;
      done = consider(current);
      for (int c = 1; !done && c < budget / 2; ++c)
        done = consider(SwingPlan(perturbed(current.params(), rng, false), config_, env.config(), current.anchor(),
                                  current.anchor_step()));
      budget -= budget / 2;
    }
    for (int c = 0; !done && c < std::max(1, budget); ++c) {
      const SwingParams p = c == 0 ? config_.swing : perturbed(config_.swing, rng, t > 0);
      done = consider(SwingPlan(p, config_, env.config(), s, t));
    }
    if (robust_plan && !(best_plan && best.score >= 0.0)) {
      best_plan = robust_plan;
      best = std::move(robust);
    }
    plan_ = *best_plan;
    predicted_ = std::move(best.states);
    predicted_from_ = t;
    last_replan_ = t;
  }

  ExpertConfig config_;
  std::uint64_t seed_ = 0;
  SwingPlan plan_;
  std::vector<State> predicted_;
  int predicted_from_ = 0;
  int last_replan_ = 0;
  AttemptWatch attempts_;
  std::optional<DiceEnv> sim_;
};

// Follows one recorded cup path chosen once per episode, at its first query, by simulating the
// recordings from that state (choose_path); afterwards only tracks it. Its actions are then a
// function of the start, the step and the state: consistent labels, as DART needs. With
// rescue_interval > 0 it also checks, that often, that the path's rest still simulates to a
// success from the state reached, and joins another recording midway when not (rescue_path):
// its actions then depend on when it switched, too.
class TrackerExpert final : public Expert {
 public:
  explicit TrackerExpert(const ExpertConfig& config) : recordings_(config.recordings), retry_(config.retry) {}
  std::string name() const override { return "tracker"; }

 private:
  void do_reset(std::uint64_t seed) override {
    seed_ = seed;
    follower_ = PathFollower();
    attempts_.clear();
  }

  Action do_act(const DiceEnv& env, const State& sensed) override {
    const int t = env.t();
    const TrackerConfig& c = recordings_->config();
    if (retry_ && attempts_.begins(env)) follower_ = PathFollower();
    if (!follower_.valid() || t < first_step_) {
      frame_ = env.get_state();
      choice_ = choose_path(*recordings_, env, planning_sim(sim_, env), seed_);
      first_step_ = last_check_ = t;
      follow(t);
    } else if (c.rescue > 0 && t - last_check_ >= c.rescue && t - start_step_ < follower_.length()) {
      last_check_ = t;
      if (!still_succeeds(follower_, env, planning_sim(sim_, env), c.hold_steps, c.controller)) {
        choice_ = rescue_path(*recordings_, env, *sim_, frame_, choice_, follower_.phase(t), seed_);
        follow(t);
      }
    }
    return follower_.act(sensed, t);
  }

  void follow(int t) {
    start_step_ = t;
    const TrackerConfig& c = recordings_->config();
    follower_ = PathFollower(recordings_->paths()[choice_.path], choice_.warp, frame_, t, c.gain, c.keep_extremes);
  }

  std::shared_ptr<const Recordings> recordings_;
  bool retry_;
  std::uint64_t seed_ = 0;
  PathFollower follower_;
  TrackerChoice choice_;
  State frame_{};
  int first_step_ = 0, start_step_ = 0, last_check_ = 0;
  AttemptWatch attempts_;
  std::optional<DiceEnv> sim_;
};

}  // namespace

void Expert::reset(std::uint64_t seed) { do_reset(seed); }

Action Expert::act(const DiceEnv& env, std::span<const Action> pending, const State* sensed) {
  const State now = env.get_state();
  require_finite(now, "expert: state");
  if (sensed) require_finite(*sensed, "expert: sensed state");
  const DiceEnv* at = &env;
  if (!pending.empty()) {
    DiceEnv& ahead = planning_sim(ahead_, env);
    ahead.restore(env.snapshot());
    for (const Action& p : pending)
      if (ahead.t() >= ahead.config().episode.max_steps || ahead.step(p).terminated) return Action::zeros(controller());
    if (ahead.t() >= ahead.config().episode.max_steps) return Action::zeros(controller());
    at = &ahead;
  }
  State feedback = at == &env ? now : at->get_state();
  if (sensed)  // what it senses, moved as the simulator moves the world through what is pending
    for (std::size_t k = 0; k < kStateDim; ++k) feedback[k] = (*sensed)[k] + feedback[k] - now[k];
  Action a = do_act(*at, feedback);
  require_finite(a, name() + " expert: action");
  return clipped(env.config(), a);
}

ExpertRegistry& ExpertRegistry::global() {
  static ExpertRegistry* registry = [] {
    auto* r = new ExpertRegistry;
    r->add({"scripted", "the tuned swing plan (scoop, swing, stop) tracked by feedback; no simulation"},
           [](const ExpertConfig& c) { return std::make_unique<ScriptedExpert>(c); });
    r->add({"mpc", "searches swing plans in the simulator from the current state; replans when off its prediction"},
           [](const ExpertConfig& c) { return std::make_unique<MpcExpert>(c); });
    r->add({"tracker", "follows the recorded cup path (of --demos) that succeeds when simulated from the start"},
           [](const ExpertConfig& c) -> std::unique_ptr<Expert> {
             if (!c.recordings)
               throw ConfigError("expert \"tracker\" needs recordings to follow (a demonstration set: --demos)");
             if (c.recordings->config().controller != c.controller)
               throw ConfigError(std::string("expert \"tracker\" answers for the ") + std::string(action_kind_name(c.controller)) +
                                 " controller, its recordings were prepared for the " +
                                 std::string(action_kind_name(c.recordings->config().controller)) +
                                 " one: its simulations would choose paths for the other");
             return std::make_unique<TrackerExpert>(c);
           });
    return r;
  }();
  return *registry;
}

void ExpertRegistry::add(ExpertInfo info, Factory factory) {
  for (const auto& e : entries_)
    if (e.info.name == info.name) throw ConfigError("expert \"" + info.name + "\" registered twice");
  entries_.push_back({std::move(info), std::move(factory)});
}

ExpertRegistry::Factory ExpertRegistry::replace(std::string_view name, Factory factory) {
  for (auto& e : entries_)
    if (e.info.name == name) return std::exchange(e.factory, std::move(factory));
  throw ConfigError("expert \"" + std::string(name) + "\" is not registered");
}

std::unique_ptr<Expert> ExpertRegistry::create(std::string_view name, const ExpertConfig& config) const {
  for (const auto& e : entries_)
    if (e.info.name == name) {
      validate(config);
      return e.factory(config);
    }
  std::string known;
  for (const auto& e : entries_) known += (known.empty() ? "" : ", ") + e.info.name;
  throw ConfigError("unknown expert \"" + std::string(name) + "\"; known: " + known);
}

std::vector<ExpertInfo> ExpertRegistry::list() const {
  std::vector<ExpertInfo> out;
  for (const auto& e : entries_) out.push_back(e.info);
  return out;
}

std::vector<ExpertInfo> expert_list() { return ExpertRegistry::global().list(); }

std::unique_ptr<Expert> make_expert(std::string_view name, const ExpertConfig& config) {
  auto expert = ExpertRegistry::global().create(name, config);
  return config.controller == ActionKind::joint_torque ? in_joint_torques(std::move(expert)) : std::move(expert);
}

ExpertEpisode run_expert_episode(Expert& expert, DiceEnv& env, bool keep_trajectory) {
  ExpertEpisode episode;
  while (env.t() < env.config().episode.max_steps) {
    const State s = env.get_state();
    const Action a = expert.act(env);
    if (keep_trajectory) {
      episode.states.push_back(s);
      episode.actions.push_back(a);
    }
    if (env.step(a).terminated) break;
  }
  episode.outcome = env.outcome();
  return episode;
}

}  // namespace dicestack
