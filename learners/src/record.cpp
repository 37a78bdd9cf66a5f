#include <dicestack/learners/record.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/memory_budget.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/episode_bytes.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

namespace dicestack {
namespace {

// The noise `fractions` asks for in world units (fractions of action_scale) for the actions of
// `kind` the expert answers. Zeros of the other kind are no noise.
Action executed_noise(const Action& fractions, ActionKind kind, const WorldConfig& world) {
  const bool none = std::all_of(fractions.begin(), fractions.end(), [](double f) { return f == 0.0; });
  if (fractions.kind() != kind && !none)
    throw ConfigError("record: the noise is given for " + std::string(action_kind_name(fractions.kind())) +
                      " actions, and the expert answers for the " + std::string(action_kind_name(kind)) + " controller");
  Action noise = Action::zeros(kind);
  if (none) return noise;
  const auto scale = action_scale(world, kind);
  for (std::size_t k = 0; k < noise.size(); ++k) {
    const double fraction = fractions[k];
    if (!(fraction >= 0.0) || !std::isfinite(fraction))
      throw ConfigError("noise for " + std::string(action_names(kind)[k]) + " must be a finite fraction >= 0, got " +
                        std::to_string(fraction));
    noise[k] = fraction * scale[k];
  }
  return noise;
}

// An episode whose expert acted behind an estimator says so in its perturbation record: its
// actions answered the estimate, which a training row (rebuilt from what the sensors gave) does
// not show, so make_dataset refuses it by name.
void mark_estimator(const RecordRequest& request, const PerturbedEnv& episode, Episode& e) {
  const PerturbationDraw& d = episode.draw();
  const bool sensed = d.observation_delay > 0 || d.action_delay > 0 ||
                      std::any_of(d.observation_noise.begin(), d.observation_noise.end(), [](double v) { return v > 0.0; });
  if (request.estimator.kind == EstimatorKind::none || !sensed) return;
  nlohmann::json record = nlohmann::json::parse(e.perturbation);
  record["estimator"] = request.estimator.kind == EstimatorKind::kalman ? "kalman" : "particle";
  e.perturbation = record.dump();
}

}  // namespace

void check_record_request(ActionKind controller, const WorldConfig& world, const RecordRequest& request) {
  if (controller == ActionKind::joint_torque && world.embodiment != Embodiment::arm)
    throw ConfigError("record: an expert answering joint torques drives an arm's joints; this world's cup floats (give "
                      "--embodiment arm)");
  if (request.estimator.kind == EstimatorKind::none) return;
  if (request.feedback != ExpertFeedback::observations)
    throw ConfigError("record: an estimator stands between the sensors and the expert's feedback, which reads the world; "
                      "give --expert-feedback observations");
  if (controller == ActionKind::joint_torque)
    throw ConfigError("record: an expert answering joint torques runs without an estimator (its feedback is turned "
                      "into torques through the world's own links, not an estimate's)");
}

std::vector<Episode> record_expert(const std::string& name, const ExpertConfig& config, const WorldConfig& world,
                                   const RecordRequest& request, Cluster& cluster) {
  make_expert(name, config);  // an unknown name fails here, before any thread starts
  validate(request.perturbation, world);
  check_record_request(config.controller, world, request);
  require_memory("recording", static_cast<std::uint64_t>(std::max(0, request.episodes)),
                 episode_memory_bound(world.episode.max_steps), "episodes");
  require_memory("record: the estimators of the episodes running at once",
                 static_cast<std::uint64_t>(resolve_threads(request.threads)), estimator_bytes(request.estimator), "episodes");
  const Action noise = executed_noise(request.noise, config.controller, world);
  const int threads = request.threads;
  const auto workers = static_cast<std::size_t>(resolve_threads(threads));
  EnvPool envs(world, threads);
  std::vector<std::unique_ptr<Expert>> experts(workers);
  std::atomic<int> finished{0};
  const int ranks = cluster.size(), total = std::max(0, request.episodes);
  return distributed_map<Episode>(
      cluster, static_cast<std::size_t>(std::max(0, request.episodes)), threads,
      [&](std::size_t i, int w) {
        auto& expert = experts[static_cast<std::size_t>(w)];
        if (!expert) expert = make_expert(name, config);
        const std::uint64_t s = training_start_seed(request.seed, request.first + i);
        PerturbedEnv episode(envs.at(w), request.perturbation, s, config.controller);
        episode.add_executed_noise(noise, derive_seed(s, 2));
        episode.use_estimator(request.estimator);
        ExpertPolicy policy(*expert, episode.env(), request.feedback);
        Episode e = rollout(episode, policy, episode.random_start(s), s, StepSource::expert);
        e.origin = "expert " + name;
        mark_estimator(request, episode, e);
        const int done = std::min(total, ++finished * ranks);
        if (request.progress && w == 0) request.progress(done, total);
        return e;
      },
      [](const Episode& e) { return episode_to_bytes(e); }, [](std::string_view b) { return episode_from_bytes(b); });
}

std::filesystem::path resolve_demo_set(const std::filesystem::path& spec, const WorldConfig& world) {
  if (spec.empty() || (spec == "builtin" && !std::filesystem::exists(spec))) return builtin_demo_set(world);
  if (spec == "human" && !std::filesystem::exists(spec)) return human_demo_set(world);
  return spec;
}

std::filesystem::path builtin_demo_set(const WorldConfig& world, int threads) {
  const std::uint64_t h = world_hash(world);
  char name[40];
  std::snprintf(name, sizeof name, "expert-v3-%08llx", static_cast<unsigned long long>(h >> 32));
  const auto dir = cache_dir() / name;
  if (std::filesystem::exists(dir / "meta.json")) return dir;

  DemoSet set;
  set.world = world;
  set.description = "Built-in demonstrations: the first " + std::to_string(kBuiltinSuccesses) +
                    " realistic successes (stacked, no wall contact) of dicestack's mpc expert from random starts";
  int batch_start = 0, tried = 0;
  while (static_cast<int>(set.episodes.size()) < kBuiltinSuccesses) {
    if (batch_start > 50 * kBuiltinSuccesses)
      throw Error("built-in demonstrations: the mpc expert found too few successes in this world");
    // Episodes batch_start.. of the seeded sequence; successes kept in index order.
    RecordRequest request;
    request.episodes = kBuiltinSuccesses;
    request.seed = derive_seed(kBuiltinSeed, static_cast<std::uint64_t>(batch_start));
    request.threads = threads;
    auto batch = record_expert("mpc", {}, world, request);
    for (auto& e : batch) {
      ++tried;
      if (e.outcome.realistic_success() && static_cast<int>(set.episodes.size()) < kBuiltinSuccesses)
        set.episodes.push_back(std::move(e));
    }
    batch_start += kBuiltinSuccesses;
  }
  set.provenance = "dicestack builtin_demo_set: expert mpc (default ExpertConfig), random starts with seeds "
                   "training_start_seed(derive_seed(" + std::to_string(kBuiltinSeed) + ", batch), i); " +
                   std::to_string(set.episodes.size()) + " successes kept of " + std::to_string(tried) + " episodes";
  write_demo_set(set, dir);
  return dir;
}

}  // namespace dicestack
