// Measures the tracker, the demonstrator made of demonstrations (docs/learners.md):
// realistic success, wall contact, which recordings it chose and how many simulations its
// search took, over random starts (evaluation_start_seed(seed, i)). Usage:
//   dicestack_tracker_bench [--demos builtin|human|DIR] [--starts N] [--seed S] [--tracker-seed T] [--threads N]
//       [--recordings K [--subset-seed S]] [--preset plain|distill] [--set NAME=VALUE]... [--probes P] [--paths N] [--no-optimise]
//       [--noise F|X,Y,W [--noise-window FROM,TO]] [--rescue N] [--smooth S] [--per-path [--ranked]] [--json]
//       [--robust K] [--robust-noise F] [--robust-warp W] [--keep-extremes] [--choices FILE.csv] [--retry]
// --recordings K keeps K recordings drawn with --subset-seed from the set (all by default).
// --tracker-seed T seeds the ranking and the refinements (0 by default; a learner gives its own seed).
// The tracker is the preset (tracker_preset, default plain) with each setting on top, in order:
// --set NAME=VALUE for any (tracker_setting_names), and --probes, --paths, ... for the same
// names with dashes.
// --noise F adds DART's executed-action noise (std F x action.scale; X,Y,W: per axis, as DART's
// default with the tracker, 0.1,0.5,0.2) to the episode that follows
// the choice (between FROM and TO, as fractions of the chosen path's length): how robust the
// choices are to a learner's errors. --per-path follows every recording as recorded (no search)
// from each start instead, with and without that noise, and lists them by successes; with
// --ranked, the paths of the ranked recordings (the variants and the refined paths among them).
// --rescue N runs the tracker expert with rescue N (closed loop on the dice) instead of
// the chosen path's follower; --retry runs it trying again once a failed attempt has come to rest
// (ExpertConfig::retry). --robust K makes robust choices (TrackerConfig::robust);
// --choices writes each start's dice x, chosen recording, warp and outcome.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/experiments/train.hpp>

using namespace dicestack;

namespace {

struct Options {
  std::string demos = "human";
  int starts = 100, threads = 0, recordings = 0;
  std::uint64_t seed = 1000, subset_seed = 0, tracker_seed = 0;
  std::string preset = "plain";        // --preset: tracker_preset's name
  std::vector<std::string> settings;   // NAME=VALUE on top, in the order given
  TrackerConfig tracker;               // the preset with the settings
  Action noise{};  // per axis, x action.scale
  double noise_from = 0.0, noise_to = 1e9;
  bool noisy() const { return noise[0] > 0.0 || noise[1] > 0.0 || noise[2] > 0.0; }
  bool per_path = false, ranked = false, json = false, retry = false;
  std::string choices;  // --choices FILE: one CSV line per start
};

// Every refined path (up to TrackerConfig::refine_restarts of them), with its validation successes.
std::string refinements(const Recordings& recordings) {
  std::string out;
  for (std::size_t p = 0; p < recordings.paths().size(); ++p)
    if (recordings.paths()[p].name.find(" (refined") != std::string::npos)
      out += (out.empty() ? "" : ", ") + recordings.paths()[p].name + " " + std::to_string(recordings.probe_successes()[p]) +
             "/" + std::to_string(recordings.probe_trials()[p]);
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
      return argv[++i];
    };
    if (a == "--demos") o.demos = next();
    else if (a == "--starts") o.starts = std::stoi(next());
    else if (a == "--seed") o.seed = std::stoull(next());
    else if (a == "--threads") o.threads = std::stoi(next());
    else if (a == "--recordings") o.recordings = std::stoi(next());
    else if (a == "--subset-seed") o.subset_seed = std::stoull(next());
    else if (a == "--tracker-seed") o.tracker_seed = std::stoull(next());
    else if (a == "--preset") o.preset = next();
    else if (a == "--set") o.settings.push_back(next());
    else if (a == "--no-optimise") o.settings.push_back("optimise=false");
    else if (a == "--keep-extremes") o.settings.push_back("keep_extremes=true");
    else if (a == "--retry") o.retry = true;
    else if (a == "--probes" || a == "--paths" || a == "--rescue" || a == "--smooth" || a == "--robust" ||
             a == "--robust-noise" || a == "--robust-warp" || a == "--shrink") {
      std::string name = a.substr(2);
      std::replace(name.begin(), name.end(), '-', '_');  // the setting's own name
      o.settings.push_back(name + "=" + next());
    }
    else if (a == "--noise") {
      const std::string v = next();
      const int n = std::sscanf(v.c_str(), "%lf,%lf,%lf", &o.noise[0], &o.noise[1], &o.noise[2]);
      if (n == 1) o.noise[1] = o.noise[2] = o.noise[0];
      else if (n != 3) throw std::runtime_error("--noise F or X,Y,W");
    }
    else if (a == "--noise-window") {
      const std::string v = next();
      if (std::sscanf(v.c_str(), "%lf,%lf", &o.noise_from, &o.noise_to) != 2) throw std::runtime_error("--noise-window FROM,TO");
    } else if (a == "--per-path") o.per_path = true;
    else if (a == "--ranked") o.ranked = true;
    else if (a == "--json") o.json = true;
    else if (a == "--choices") o.choices = next();
    else throw std::runtime_error("unknown argument " + a);
  }
  if (o.starts < 1) throw std::runtime_error("--starts must be >= 1");
  o.tracker = tracker_config(o.preset, o.settings);
  return o;
}

// Follows `follower` (or, given, `expert`) from env's state to the end of the episode, with the
// options' noise.
Outcome follow(DiceEnv& env, const PathFollower& follower, const Options& o, std::uint64_t noise_seed, bool noisy,
               Expert* expert = nullptr) {
  Rng rng(noise_seed);
  const int first = env.t();
  while (env.t() < env.config().episode.max_steps) {
    Action a = expert ? expert->act(env) : follower.act(env.get_state(), env.t());
    const double at = static_cast<double>(env.t() - first) / std::max(1, follower.length());
    if (noisy && at >= o.noise_from && at < o.noise_to)
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] += o.noise[k] * env.config().action.scale[k] * rng.normal();
    if (env.step(a).terminated) break;
  }
  return env.outcome();
}

int per_path(const std::vector<Episode>& episodes, const WorldConfig& world, const Options& o) {
  TrackerConfig unranked = o.tracker;  // the paths as the tracker follows them (smoothed), no ranking
  unranked.probes = 0;
  const Recordings recordings(cup_paths(episodes), world, o.ranked ? o.tracker : unranked, o.tracker_seed, o.threads);
  const auto& paths = recordings.paths();
  const auto n = static_cast<std::size_t>(o.starts);
  std::vector<int> ok(paths.size() * n), ok_noisy(paths.size() * n);
  EnvPool envs(world, o.threads);
  parallel_for(paths.size() * n, o.threads, [&](std::size_t item, int w) {
    const std::uint64_t s = evaluation_start_seed(o.seed, item % n);
    for (const bool noisy : {false, true}) {
      DiceEnv& env = envs.at(w);
      env.reset_to(random_start_state(world, s), s);
      const PathFollower follower(paths[item / n], {}, env.get_state(), 0, o.tracker.gain, o.tracker.keep_extremes);
      (noisy ? ok_noisy : ok)[item] = follow(env, follower, o, derive_seed(s, 2), noisy).realistic_success();
    }
  });
  std::vector<std::tuple<int, int, int, std::string>> rows;
  for (std::size_t p = 0; p < paths.size(); ++p) {
    int a = 0, b = 0, both = 0;
    for (std::size_t i = 0; i < n; ++i)
      a += ok[p * n + i], b += ok_noisy[p * n + i], both += ok[p * n + i] && ok_noisy[p * n + i];
    rows.emplace_back(a, b, both, paths[p].name);
  }
  std::sort(rows.rbegin(), rows.rend());
  std::printf("recording: realistic successes of %d starts as recorded, with noise %g,%g,%g, and both\n", o.starts,
              o.noise[0], o.noise[1], o.noise[2]);
  for (const auto& [a, b, both, name] : rows) std::printf("%s %d %d %d\n", name.c_str(), a, b, both);
  return 0;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  const WorldConfig world;
  const std::vector<Episode> episodes =
      pick_recordings(read_demo_set(resolve_demo_set(o.demos, world)).episodes, o.recordings, o.subset_seed);
  if (o.per_path) return per_path(episodes, world, o);

  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const auto recordings = make_recordings(episodes, world, o.tracker, o.tracker_seed, o.threads);
  const double rank_seconds = std::chrono::duration<double>(clock::now() - t0).count();

  struct Result {
    TrackerChoice choice;
    Outcome outcome;
  };
  std::vector<Result> results(static_cast<std::size_t>(o.starts));
  EnvPool envs(world, o.threads), sims(world, o.threads);
  ExpertConfig expert_config;
  expert_config.recordings = recordings;
  expert_config.retry = o.retry;
  std::vector<std::unique_ptr<Expert>> experts;
  for (int w = 0; w < resolve_threads(o.threads); ++w) experts.push_back(make_expert("tracker", expert_config));
  const auto t1 = clock::now();
  parallel_for(results.size(), o.threads, [&](std::size_t i, int w) {
    DiceEnv& env = envs.at(w);
    const std::uint64_t s = evaluation_start_seed(o.seed, i);
    env.reset_to(random_start_state(world, s), s);
    Result& r = results[i];
    r.choice = choose_path(*recordings, env, sims.at(w), s);
    const PathFollower follower(recordings->paths()[r.choice.path], r.choice.warp, env.get_state(), env.t(),
                                o.tracker.gain, o.tracker.keep_extremes);
    Expert* expert = o.tracker.rescue > 0 || o.retry ? experts[static_cast<std::size_t>(w)].get() : nullptr;
    if (expert) expert->reset(s);
    r.outcome = follow(env, follower, o, derive_seed(s, 2), o.noisy(), expert);
  });
  const double seconds = std::chrono::duration<double>(clock::now() - t1).count();
  if (!o.choices.empty()) {
    std::FILE* f = std::fopen(o.choices.c_str(), "w");
    if (!f) throw std::runtime_error(o.choices + ": cannot write");
    std::fprintf(f, "start,dice_mean_x,path,time_scale,offset,amplitude,chosen_success,realistic_success,wall_contact\n");
    for (std::size_t i = 0; i < results.size(); ++i) {
      const State s0 = random_start_state(world, evaluation_start_seed(o.seed, i));
      const double x = (s0[3] + s0[9] + s0[15]) / 3.0;
      const Result& r = results[i];
      std::fprintf(f, "%zu,%.4f,%s,%.4f,%.4f,%.4f,%d,%d,%d\n", i, x, recordings->paths()[r.choice.path].name.c_str(),
                   r.choice.warp.time_scale, r.choice.warp.offset, r.choice.warp.amplitude, r.choice.success ? 1 : 0,
                   r.outcome.realistic_success() ? 1 : 0, r.outcome.wall_contact ? 1 : 0);
    }
    std::fclose(f);
  }

  int success = 0, wall = 0, found = 0, warped = 0, sims_total = 0, sims_max = 0;
  std::map<std::string, int> chosen;
  for (const auto& r : results) {
    success += r.outcome.realistic_success();
    wall += r.outcome.wall_contact;
    found += r.choice.success;
    warped += r.choice.warp.time_scale != 1.0 || r.choice.warp.offset != 0.0 || r.choice.warp.amplitude != 1.0;
    sims_total += r.choice.simulations;
    sims_max = std::max(sims_max, r.choice.simulations);
    ++chosen[recordings->paths()[r.choice.path].name];
  }
  std::vector<std::pair<int, std::string>> by_count;
  for (const auto& [name, n] : chosen) by_count.emplace_back(n, name);
  std::sort(by_count.rbegin(), by_count.rend());
  const double ms = 1e3 * seconds / o.starts;
  if (o.json) {
    std::printf("{\"demos\": \"%s\", \"recordings\": %zu, \"starts\": %d, \"seed\": %llu, \"threads\": %d, \"noise\": [%g, %g, %g], "
                "\"realistic_success\": %d, \"wall_contact\": %d, \"search_found\": %d, \"warped\": %d, "
                "\"distinct_paths\": %zu, \"simulations_mean\": %.2f, \"simulations_max\": %d, \"rank_seconds\": %.3f, "
                "\"seconds\": %.3f, \"ms_per_start\": %.2f}\n",
                o.demos.c_str(), episodes.size(), o.starts, static_cast<unsigned long long>(o.seed),
                resolve_threads(o.threads), o.noise[0], o.noise[1], o.noise[2], success, wall, found, warped, chosen.size(),
                static_cast<double>(sims_total) / o.starts, sims_max, rank_seconds, seconds, ms);
    return 0;
  }
  std::printf("tracker on %s (%zu recordings), %d starts from evaluation seed %llu, %d threads, noise %g,%g,%g\n",
              o.demos.c_str(), episodes.size(), o.starts, static_cast<unsigned long long>(o.seed),
              resolve_threads(o.threads), o.noise[0], o.noise[1], o.noise[2]);
  std::printf("ranking: %d probe starts per recording, %.2f s; followed: %s\n", o.tracker.probes, rank_seconds,
              followed_recordings(*recordings).c_str());
  if (const std::string refined = refinements(*recordings); !refined.empty()) std::printf("refined: %s\n", refined.c_str());
  std::printf("realistic success %d / %d, wall contact %d; the search found a success for %d, %d of them warped\n",
              success, o.starts, wall, found, warped);
  std::printf("simulations per start: mean %.2f, max %d; %.3f s in all (%.2f ms per start)\n",
              static_cast<double>(sims_total) / o.starts, sims_max, seconds, ms);
  std::printf("distinct recordings chosen: %zu; most chosen:", chosen.size());
  for (std::size_t k = 0; k < std::min<std::size_t>(8, by_count.size()); ++k)
    std::printf(" %s %d", by_count[k].second.c_str(), by_count[k].first);
  std::printf("\n");
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "dicestack_tracker_bench: %s\n", e.what());
  return 1;
}
