#include <dicestack/learners/evaluate.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/memory_budget.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/episode_bytes.hpp>

namespace dicestack {

InitialPush initial_push_from(std::string_view text) {
  if (text == "none") return InitialPush::none;
  if (text == "left") return InitialPush::left;
  if (text == "right") return InitialPush::right;
  throw ConfigError("initial push \"" + std::string(text) + "\" is not one of none, left, right");
}

Episode rollout(PerturbedEnv& world, Policy& policy, const State& start, std::uint64_t seed, StepSource source,
                const RolloutOptions& options) {
  Episode e;
  e.seed = seed;
  e.origin = policy.name();
  DiceEnv& env = world.env();
  const bool channelled = world.channelled();
  std::vector<State> seen;         // what the policy was shown, when that is not the true states
  std::vector<ArmLinks> seen_links;  // and the links shown with it (an estimator's are its own)
  std::vector<Action> applied, pending, unseen;
  policy.attach(env);
  const State shown = world.reset_to(start, seed);
  // An arm's joint encoders read its links exactly and at once: only the scene's sensing is
  // perturbed. Behind an estimator the policy is shown the links of the state it estimates.
  const bool arm = env.config().embodiment == Embodiment::arm;
  e.states.push_back(env.get_state());
  if (arm) e.links.push_back(env.world().arm_links());
  const auto show = [&](const State& s) {
    seen.push_back(s);
    if (arm) seen_links.push_back(world.shown_links());
  };
  if (channelled) show(shown);
  policy.reset(seed);
  while (true) {
    if (options.before_step) options.before_step(env, applied.size());
    if (channelled) {
      pending.assign(world.pending().begin(), world.pending().end());
      unseen.assign(world.unseen().begin(), world.unseen().end());
    }
    Action a = policy.act(History{channelled ? seen : e.states, applied, pending, unseen, channelled ? seen_links : e.links});
    if (applied.empty() && options.push != InitialPush::none) {
      if (a.kind() != ActionKind::cup) throw InputError("an initial push is a cup velocity change; this policy answers joint torques");
      a[0] += options.push == InitialPush::left ? -1.0 : 1.0;
    }
    a = world.clip(a);
    const auto label = policy.label();
    e.actions.push_back(label ? label->label : a);
    e.sources.push_back(label ? label->source : source);
    const PerturbedStep step = world.step(a);
    const StepResult& r = step.result;
    applied.push_back(r.applied);
    e.rewards.push_back(r.reward);
    if (arm) e.joint_torques.push_back(env.world().arm_step_torques());
    if (r.terminated || r.truncated || applied.size() == options.max_steps) {
      e.final_state = r.observation;
      if (arm) e.final_links = env.world().arm_links();
      e.terminated = r.terminated;
      e.truncated = !r.terminated;  // the time limit or options.max_steps
      break;
    }
    e.states.push_back(r.observation);
    if (arm) e.links.push_back(env.world().arm_links());
    if (channelled) show(step.shown);
  }
  e.outcome = env.outcome();
  if (world.perturbed())
    e.perturbation = draw_to_json(world.draw(), e.actions.empty() ? ActionKind::cup : e.actions.front().kind());
  return e;
}

Episode rollout(DiceEnv& env, Policy& policy, const State& start, std::uint64_t seed, StepSource source,
                const RolloutOptions& options) {
  PerturbedEnv world(env);
  return rollout(world, policy, start, seed, source, options);
}

Rate wilson(int successes, int trials) {
  if (trials <= 0) return {};
  const double z = 1.96, n = trials, p = successes / n;
  const double denom = 1.0 + z * z / n;
  const double centre = (p + z * z / (2.0 * n)) / denom;
  const double half = z * std::sqrt(p * (1.0 - p) / n + z * z / (4.0 * n * n)) / denom;
  return {p, std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

namespace {

// A policy that measures how long its inner policy takes.
class TimedPolicy final : public Policy {
 public:
  TimedPolicy(Policy& inner, double& seconds) : inner_(inner), seconds_(seconds) {}
  void reset(std::uint64_t seed) override { inner_.reset(seed); }
  void attach(const DiceEnv& env) override { inner_.attach(env); }
  Action act(const History& h) override {
    const auto t0 = std::chrono::steady_clock::now();
    const Action a = inner_.act(h);
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return a;
  }
  std::string name() const override { return inner_.name(); }
  std::optional<Labelled> label() const override { return inner_.label(); }

 private:
  Policy& inner_;
  double& seconds_;
};

EvalStats summarise(const std::vector<Episode>& eps, double policy_seconds, double wall) {
  EvalStats s;
  s.episodes = static_cast<int>(eps.size());
  int in3 = 0, stacked = 0, walls = 0, success = 0;
  double cup = 0.0, steps = 0.0;
  for (const auto& e : eps) {
    cup += e.outcome.dice_in_cup;
    in3 += e.outcome.dice_in_cup == 3;
    stacked += e.outcome.stacked;
    walls += e.outcome.wall_contact;
    success += e.outcome.realistic_success();
    steps += static_cast<double>(e.size());
  }
  const double n = std::max(1, s.episodes);
  s.dice_in_cup_mean = cup / n;
  s.dice_in_cup_3 = wilson(in3, s.episodes);
  s.stacked = wilson(stacked, s.episodes);
  s.wall_contact = wilson(walls, s.episodes);
  s.realistic_success = wilson(success, s.episodes);
  s.mean_length = steps / n;
  s.policy_us_per_step = steps > 0 ? 1e6 * policy_seconds / steps : 0.0;
  s.seconds = wall;
  return s;
}

}  // namespace

namespace {

// One rollout and the time its policy took, as it travels between ranks.
struct Timed {
  Episode episode;
  double policy_seconds = 0.0;
  int wall_step = -1;
};

std::string pack_timed(const Timed& t) {
  Packer p;
  pack_episode(p, t.episode);
  p.put(t.policy_seconds).put(t.wall_step);
  return p.take();
}

Timed unpack_timed(std::string_view bytes) {
  Unpacker u(bytes, "rollout");
  Timed t;
  t.episode = unpack_episode(u);
  t.policy_seconds = u.get<double>();
  t.wall_step = u.get<int>();
  return t;
}

std::string pack_one(const Episode& e) { return episode_to_bytes(e); }
Episode unpack_one(std::string_view bytes) { return episode_from_bytes(bytes); }

}  // namespace

std::string estimator_for(const std::string& asked, const Model& model) {
  if (!asked.empty()) {
    estimator_config(asked);
    return asked;
  }
  const auto named = model.record.find("estimator");
  if (named == model.record.end()) return "none";
  try {
    estimator_config(named->second);
  } catch (const Error& e) {
    throw ConfigError(std::string("the model's record names an estimator this build does not know: ") + e.what());
  }
  return named->second;
}

void check_evaluation(const WorldConfig& world, const EvalRequest& request) {
  validate(request.perturbation, world);
  if (request.actions == ActionKind::joint_torque) {
    const std::string what = "evaluate: a policy in joint torques";
    if (world.embodiment != Embodiment::arm) throw ConfigError(what + " drives an arm's joints: give --embodiment arm");
    if (request.estimator.kind == EstimatorKind::particle)
      throw ConfigError(what + ": the particle filter rebuilds its worlds without the arm's links; use --estimator kalman");
    if (request.push != InitialPush::none) throw ConfigError(what + ": an initial push is a cup velocity change");
  }
  require_memory("evaluate", static_cast<std::uint64_t>(std::max(0, request.episodes)),
                 episode_memory_bound(world.episode.max_steps), "rollouts");
  check_threads(request.threads, "evaluate: threads");
  require_memory("evaluate: the estimators of the episodes running at once",
                 static_cast<std::uint64_t>(resolve_threads(request.threads)), estimator_bytes(request.estimator),
                 "episodes");
}

EvalStats evaluate(const PolicyFactory& make_policy, const WorldConfig& world, const EvalRequest& request,
                   Cluster& cluster) {
  check_evaluation(world, request);
  RolloutOptions options;
  options.push = request.push;
  options.max_steps = request.max_steps;
  const int episodes = std::max(0, request.episodes);
  const int workers = resolve_threads(request.threads);
  EnvPool envs(world, request.threads);
  std::vector<std::unique_ptr<Policy>> policies(static_cast<std::size_t>(workers));
  std::atomic<int> finished{0};
  const int ranks = cluster.size();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Timed> done = distributed_map<Timed>(
      cluster, static_cast<std::size_t>(episodes), request.threads,
      [&](std::size_t i, int w) {
        const auto slot = static_cast<std::size_t>(w);
        if (!policies[slot]) policies[slot] = make_policy();
        Timed t;
        TimedPolicy timed(*policies[slot], t.policy_seconds);
        const std::uint64_t episode_seed = evaluation_start_seed(request.seed, i);
        PerturbedEnv episode(envs.at(w), request.perturbation, episode_seed, request.actions);
        episode.use_estimator(request.estimator);
        RolloutOptions episode_options = options;
        const State start = episode.random_start(episode_seed);
        // Only when results are asked for (a call per step): before step k the outcome covers
        // steps 0..k-1, so the first k that sees a wall names step k-1.
        if (request.results)
          episode_options.before_step = [&t](const DiceEnv& e, std::size_t k) {
            if (t.wall_step < 0 && e.outcome().wall_contact) t.wall_step = static_cast<int>(k) - 1;
          };
        t.episode = rollout(episode, timed, start, episode_seed, StepSource::policy, episode_options);
        if (t.wall_step < 0 && t.episode.outcome.wall_contact) t.wall_step = static_cast<int>(t.episode.size()) - 1;
        if (request.progress) request.progress(std::min(episodes, ++finished * ranks), episodes);
        return t;
      },
      pack_timed, unpack_timed);
  std::vector<Episode> eps(done.size());
  double total_policy = 0.0;
  if (request.results) request.results->clear();
  for (std::size_t i = 0; i < done.size(); ++i) {
    total_policy += done[i].policy_seconds;
    if (request.results) {
      const Episode& e = done[i].episode;
      EpisodeResult r;
      r.index = static_cast<int>(i);
      r.seed = e.seed;
      r.success = e.outcome.realistic_success();
      r.stacked = e.outcome.stacked;
      r.wall_contact = e.outcome.wall_contact;
      r.dice_in_cup = e.outcome.dice_in_cup;
      r.wall_step = done[i].wall_step;
      r.length = static_cast<int>(e.size());
      for (double x : e.rewards) r.reward += x;
      request.results->push_back(r);
    }
    eps[i] = std::move(done[i].episode);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EvalStats stats = summarise(eps, total_policy, wall);
  if (request.rollouts) *request.rollouts = std::move(eps);
  return stats;
}

namespace {

// Rolls a policy out from every demonstration's first state. Long recordings must not be cut by
// the time limit; leave two seconds to settle.
std::vector<Episode> rollouts_from_demos(const std::function<std::unique_ptr<Policy>(std::size_t)>& make_policy,
                                         const std::vector<Episode>& demos, const WorldConfig& config, int threads,
                                         Cluster& cluster) {
  WorldConfig world = config;
  for (const auto& d : demos)
    world.episode.max_steps = std::max(world.episode.max_steps, static_cast<int>(d.size()) + 60);
  EnvPool envs(world, threads);
  return distributed_map<Episode>(
      cluster, demos.size(), threads,
      [&](std::size_t i, int w) {
        const auto policy = make_policy(i);
        return rollout(envs.at(w), *policy, demos[i].states.front(), demos[i].seed, StepSource::policy);
      },
      pack_one, unpack_one);
}

}  // namespace

EvalStats evaluate_playback(const std::vector<Episode>& demos, const WorldConfig& world, int threads, Cluster& cluster) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto eps = rollouts_from_demos([&](std::size_t i) { return std::make_unique<PlaybackPolicy>(demos[i]); },
                                       demos, world, threads, cluster);
  return summarise(eps, 0.0, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

Tracking track_demos(const PolicyFactory& make_policy, const std::vector<Episode>& demos, const WorldConfig& world,
                     int threads, Cluster& cluster) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto eps = rollouts_from_demos([&](std::size_t) { return make_policy(); }, demos, world, threads, cluster);
  Tracking t;
  for (std::size_t i = 0; i < demos.size(); ++i) {
    const std::size_t n = std::min(demos[i].size(), eps[i].size());
    double sum = 0.0;
    for (std::size_t k = 0; k < n; ++k) sum += std::sqrt(tracking_distance_sq(eps[i].states[k], demos[i].states[k], world.cost));
    t.deviation += sum / static_cast<double>(std::max<std::size_t>(n, 1)) / static_cast<double>(demos.size());
  }
  t.stats = summarise(eps, 0.0, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return t;
}

OutcomeCounts outcome_counts(const EvalStats& s) {
  auto count = [&](const Rate& r) { return static_cast<int>(std::lround(r.value * s.episodes)); };
  return {s.episodes, count(s.stacked), count(s.wall_contact), count(s.realistic_success)};
}

}  // namespace dicestack
