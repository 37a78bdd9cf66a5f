#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <optional>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/learners/corrector.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

#include "checkpoint.hpp"
#include "dad_code.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;

// Everything a run does, resolved from its options once, before any work (make_plan); the
// model records it as "dad_settings".
struct DadPlan {
  CodeParts code;
  int windows = 10, per_window = 3;
  CorrectionTarget aim = CorrectionTarget::cup;
  std::string corrector;
  CorrectorOptions search;
  bool filter = true, keep_best = true;
  bool from_training = false;  // targets: the tracker's episodes from training starts, else demonstrations
  std::size_t demos = 0;       // demonstrations as targets (0: all)
  int episodes = 0;            // training starts the tracker runs from
  bool retry = false;          // the tracker tries again (from training starts)
  ActionKind action_kind = ActionKind::cup;  // what the map answers, and so the corrections' labels

  std::string summary() const {
    static const char* aims[] = {"state", "cup", "dice"};
    char text[320];
    std::snprintf(text, sizeof text,
                  "windows=%d, iterations=%d, target=%s, corrector=%s, corrector_iterations=%d, evaluations=%d, sigma0=%g, "
                  "population=%d, filter=%s, keep_best=%s, starts=%s, demos=%zu, episodes=%d, retry=%s",
                  windows, per_window, aims[static_cast<int>(aim)], corrector.c_str(), search.iterations, search.evaluations,
                  search.sigma0, search.population, filter ? "true" : "false", keep_best ? "true" : "false",
                  from_training ? "training" : "demonstrations", demos, episodes, retry ? "true" : "false");
    return text;
  }
};

// One window to correct: where in which demonstration, and the problem the corrector solves.
struct Task {
  std::size_t demo = 0;
  std::size_t t = 0;
  CorrectionProblem problem;
};

// A correction carries the rollout before its window as history (the policy's steps): those are
// not rows. A demonstration's steps all are, whoever chose them.
bool is_row(const Episode& e, std::size_t t) {
  return e.sources[t] != StepSource::policy || e.sources.back() != StepSource::correction;
}

// The iteration a correction was made at, from its origin ("dad iteration <k>: ...", which a
// checkpoint keeps where it renames the episodes); 0 for a demonstration.
constexpr std::string_view kMadeAt = "dad iteration ";
int made_at(const Episode& e) {
  if (e.origin.rfind(kMadeAt, 0) != 0) return 0;
  try {
    return std::stoi(e.origin.substr(kMadeAt.size()));
  } catch (const std::exception&) {
    return 0;
  }
}

// The starts a policy DaD trained from training starts is scored from: as many training starts
// as it has targets, after theirs. Its targets' own starts, where its corrections were made,
// flatter it (knn from the 68 recordings: 50 % there, 5 % from evaluation starts).
std::vector<Episode> scoring_starts(const WorldConfig& world, std::uint64_t seed, std::size_t after, std::size_t count) {
  std::vector<Episode> out(count);
  for (std::size_t i = 0; i < count; ++i) {
    out[i].name = "scoring_start_" + std::to_string(i);
    out[i].seed = training_start_seed(seed, after + i);
    out[i].states = {random_start_state(world, out[i].seed)};
  }
  return out;
}

// Where a DaD run stands between iterations: its data, its curve, the policy now and the best
// so far, and its corrections' counts. What a checkpoint saves.
struct DadRun {
  std::vector<Episode> data;  // the demonstrations, then each correction once
  LearnResult result;
  std::shared_ptr<Model> model, best;
  double best_deviation = 0.0;
  int best_iteration = 0, first = 1;
  std::size_t corrections = 0, filtered = 0;
  bool from_training = false;

  // The iteration's policy is better: from training starts, it stacks from more of its scoring
  // starts (a tie keeps the earlier, with fewer corrections); else it follows the held-out
  // demonstrations closer.
  bool better(const CurvePoint& p) const {
    if (!from_training) return p.deviation < best_deviation;
    return p.realistic_success_rate > result.curve[static_cast<std::size_t>(best_iteration)].realistic_success_rate;
  }
  // Adds iteration k's point to the curve, keeping its policy when it is the best so far.
  void add(const CurvePoint& point, int k) {
    const bool improved = better(point);
    result.curve.push_back(point);
    if (!improved) return;
    best = model;
    best_deviation = point.deviation;
    best_iteration = k;
  }
};

// DaD with windowed annealing (paper VI-E, DESIGN "Learners"): roll the policy out from each
// demonstration's first state; at every w-th step, from the policy's own drifted world, find
// the next w actions that bring the simulated cup back onto the demonstration's cup path (or,
// with target=state, all simulated states onto the demonstration's: eq. 11 as written);
// add those (state, action) pairs to the data once (eq. 10); refit. Windows grow from 1/10 of
// the demonstration to all of it, with a few iterations each. `faithful` runs the paper's code
// instead, difference by difference (docs/notebook/2026-11-27-learners-page-history.md, "DaD as
// the paper's code runs it"; in brief: docs/learners.md, "DaD in the paper's setting").
class Dad final : public Learner {
 public:
  // A bad `faithful` is refused where the options are parsed, before any work.
  Dad(std::string name, Params params) : Learner(std::move(name), std::move(params)) {
    code_parts(this->params().choice("faithful"));
  }

  LearnResult learn(const LearnContext& c) const override {
    require_learnable_map("dad", params(), feature_map(c.features));  // before any work
    const DadPlan plan = make_plan(c.features);
    const bool from_training = plan.from_training;
    std::string followed;  // from training starts: the recordings the tracker followed
    const int total = plan.windows * plan.per_window;
    const std::vector<Episode> targets =
        from_training ? tracker_targets(c, plan, followed) : pick_targets(c.demos, plan.demos, c.world.cost);
    // From training starts the policy is scored by its success from starts it was not trained on.
    LearnContext measured = c;
    if (from_training) measured.held_out = scoring_starts(c.world, c.seed, static_cast<std::size_t>(plan.episodes), targets.size());
    const std::optional<State> fixed_start = plan.code.start ? std::optional<State>(paper_start_state(c.world)) : std::nullopt;
    // Long recordings must not be cut by the time limit.
    WorldConfig world = c.world;
    for (const auto& d : targets) world.episode.max_steps = std::max(world.episode.max_steps, static_cast<int>(d.size()) + 1);

    DadRun run = start_run(c, plan, targets, measured);
    run.from_training = from_training;
    EnvPool envs(world, c.threads);
    const auto corrector = make_corrector(plan.corrector, plan.search);
    for (int k = run.first; k <= total; ++k) {
      const int window = (k - 1) / plan.per_window + 1;
      auto report = [&](const char* phase, int done, int of) {
        if (c.progress)
          c.progress({phase, k, total, window, plan.windows, done, of, (k - 1 + (of ? static_cast<double>(done) / of : 0.0)) / total});
      };
      report("rollouts", 0, 0);
      std::vector<Episode> rollouts;
      const std::vector<Task> tasks = policy_tasks(*run.model, targets, plan, window, fixed_start, envs, c.threads, rollouts);
      const std::vector<Correction> fixes = correct_windows(c, *corrector, envs, tasks, k, report);
      keep_corrections(plan, tasks, fixes, targets, rollouts, k, c.features != "state", run);
      report("fit", 0, 1);
      const std::vector<Episode> fitted = fit_data(run.data, plan, k);
      run.model = fit_model(c, fitted, derive_seed(c.seed, static_cast<std::uint64_t>(k)), is_row);
      CurvePoint point = measure_policy(run.model, measured, targets, k, rows_of(fitted));
      point.window = window;
      run.add(point, k);
      if (!c.checkpoint_dir.empty() && c.cluster->is_root()) save_state(c, k, run);
    }
    const std::shared_ptr<Model> chosen = plan.keep_best ? run.best : run.model;
    chosen->record["learner"] = "dad";
    chosen->record["dad_iteration"] = std::to_string(plan.keep_best ? run.best_iteration : total);
    chosen->record["dad_targets"] = std::to_string(targets.size());
    chosen->record["dad_scored_on"] = from_training ? "training starts " + std::to_string(plan.episodes) + " to " +
                                                          std::to_string(plan.episodes + static_cast<int>(targets.size()) - 1) +
                                                          ", which no target used (realistic success)"
                                      : c.held_out.empty() ? "targets"
                                                           : std::to_string(c.held_out.size()) + " held-out demonstrations";
    if (from_training) {
      chosen->record["dad_starts"] = "training";
      chosen->record["tracker_followed"] = followed;
    }
    chosen->record["dad_corrections_kept"] = std::to_string(run.corrections);
    chosen->record["dad_corrections_filtered"] = std::to_string(run.filtered);
    if (plan.code.any()) chosen->record["dad_faithful"] = params().choice("faithful");
    chosen->record["dad_settings"] = plan.summary();  // the options as this run used them
    run.result.model = chosen;
    return run.result;
  }

  static std::vector<ParamSpec> schema() {
    std::vector<ParamSpec> out{{"windows", ParamType::integer, "10", 1, 1000, "window sizes: k/windows of each demonstration, k = 1..windows", {}},
            {"iterations", ParamType::integer, "3", 1, 1000, "iterations per window", {}},
            {"corrector", ParamType::choice, "cmaes", 0, 0,
             "how each window's actions are found: an optimiser, or track (the tracker's feedback law, no search; a map in "
             "joint torques takes track alone)",
             corrector_names()},
            {"target", ParamType::choice, "cup", 0, 0,
             "what corrections steer back to: cup (the recording's cup path) or state (all its recorded states, eq. 11 "
             "as the paper wrote it)", {"cup", "state"}},
            {"corrector_iterations", ParamType::integer, "50", 1, 100000, "generations per correction", {}},
            {"sigma0", ParamType::real, "0.25", 1e-6, 100, "initial spread around the policy's actions, scaled action units", {}},
            {"population", ParamType::integer, "0", 0, 100000, "candidates per generation; 0: 4 + floor(3 ln n)", {}},
            {"demos", ParamType::integer, "3", 0, 1000000,
             "demonstrations to start from and correct towards, picked far apart by first state (the paper used 3); 0: all", {}},
            {"filter", ParamType::boolean, "true", 0, 1, "drop corrections that do not beat the policy's own actions", {}},
            {"keep_best", ParamType::boolean, "true", 0, 1,
             "return the iteration's policy that follows the held-out demonstrations best (starts=training: that stacks "
             "from most training starts no target used)", {}},
            {"starts", ParamType::choice, "demos", 0, 0,
             "where rollouts start and what their corrections aim at: demos (each target demonstration's first state, "
             "its recorded states) or training (random training starts, each aiming at the recording's cup path the "
             "tracker chooses there: DaD from any start; default --features state+clock+start_state@dice+retry/position)",
             {"demos", "training"}},
            {"episodes", ParamType::integer, "300", 1, 1000000, "starts=training: how many training starts", {}},
            retry_param_spec(),
            {"faithful", ParamType::text, "false", 0, 0,
             "true: run DaD as the paper's code does; or some of its parts joined by '+': start (one fixed start), label "
             "(one step at every step, to the recording's next state), cost (the dice and the cup's velocity), schedule "
             "(10 growing prefixes x 5 refits, the last kept), search (CMA-ES from a random point, sigma0 0.8, 5000 "
             "evaluations), duplicates (every refit appends every correction again), units (its units: rollouts act 100, "
             "10, 0.5 times the policy's actions, corrections are labelled 0.01, 0.1, 2 times theirs)", {}}};
    for (auto& p : tracker_param_specs()) out.push_back(std::move(p));
    return out;
  }

  // From training starts the policy plays a recording's cup path, as DART's with the tracker does.
  std::string preferred_features() const override {
    return params().choice("starts") == "training" ? "state+clock+start_state@dice+retry" + std::string(kPositionTargetSuffix)
                                                   : std::string();
  }

 private:
  // A fresh run (the demonstrations, the first fit, its point), or the checkpoint's.
  DadRun start_run(const LearnContext& c, const DadPlan& plan, const std::vector<Episode>& targets,
                   const LearnContext& measured) const {
    DadRun run;
    run.data = targets;
    if (const auto state = load_checkpoint_state(c, "dad.json", checkpoint_settings(c, plan.from_training))) {
      run.first = state->iteration() + 1;
      run.data = state->data();
      run.result.curve = state->curve();
      run.best_iteration = static_cast<int>(state->integer("best_iteration", 0, state->iteration()));
      run.best_deviation = state->number("best_deviation");
      run.best = std::make_shared<Model>(load_model(c.checkpoint_dir / state->file("best_model"), *c.registry));
      run.corrections = static_cast<std::size_t>(state->integer("corrections_kept", 0, INT64_MAX));
      run.filtered = static_cast<std::size_t>(state->integer("corrections_filtered", 0, INT64_MAX));
    }
    run.model = fit_model(c, fit_data(run.data, plan, run.first - 1), derive_seed(c.seed, static_cast<std::uint64_t>(run.first - 1)),
                          is_row);
    if (run.first == 1) {
      run.result.curve.push_back(measure_policy(run.model, measured, targets, 0, rows_of(run.data)));
      run.best = run.model;
      run.best_deviation = run.result.curve.back().deviation;
    }
    return run;
  }

  // Iteration k's corrections of its windows. Every rank cut the same windows (the rollouts are
  // deterministic); the corrections, the heavy part, are dealt among the ranks by window length
  // and gathered in index order.
  template <class Report>
  std::vector<Correction> correct_windows(const LearnContext& c, const Corrector& corrector, EnvPool& envs,
                                          const std::vector<Task>& tasks, int k, const Report& report) const {
    std::atomic<int> finished{0};
    const int ranks = c.cluster->size();
    const std::uint64_t round_seed = derive_seed(c.seed, 1000003u + static_cast<std::uint64_t>(k));
    std::vector<double> cost(tasks.size());
    for (std::size_t i = 0; i < tasks.size(); ++i) cost[i] = static_cast<double>(tasks[i].problem.target.size());
    return distributed_map<Correction>(
        *c.cluster, tasks.size(), c.threads,
        [&](std::size_t i, int w) {
          Correction fix = corrector.correct(envs.at(w), tasks[i].problem, derive_seed(round_seed, i));
          const int done = std::min(static_cast<int>(tasks.size()), ++finished * ranks);
          if (w == 0) report("corrections", done, static_cast<int>(tasks.size()));
          return fix;
        },
        pack_correction, unpack_correction, ranks > 1 ? cost : std::vector<double>{});
  }

  // Adds iteration k's corrections to the data, once each (or, as the paper's code labels,
  // every step of each window), and counts them. `with_history`: a window cut from the middle
  // of a rollout carries the rollout before it, for a map that reads more than the current state.
  static void keep_corrections(const DadPlan& plan, const std::vector<Task>& tasks, const std::vector<Correction>& fixes,
                               const std::vector<Episode>& targets, const std::vector<Episode>& rollouts, int k,
                               bool with_history, DadRun& run) {
    std::vector<Episode> made;
    if (plan.code.label) {
      made = step_corrections(tasks, fixes, targets, k);
      run.corrections += tasks.size();
    } else {
      for (std::size_t i = 0; i < tasks.size(); ++i) {
        if (plan.filter && !(fixes[i].cost < fixes[i].warm_cost)) {
          ++run.filtered;
          continue;
        }
        made.push_back(as_episode(fixes[i], targets[tasks[i].demo], tasks[i].t, k,
                                  with_history ? &rollouts[tasks[i].demo] : nullptr));
        ++run.corrections;
      }
    }
    for (auto& e : made) {
      if (plan.code.units)
        for (std::size_t t = 0; t < e.size(); ++t)
          if (e.sources[t] == StepSource::correction) e.actions[t] = scaled(e.actions[t], kCodeLabelUnits);
      run.data.push_back(std::move(e));
    }
  }

  // What a checkpoint must match to be resumed: the run's settings and, from training starts,
  // where its iterations are scored (a checkpoint that scored them on its targets' starts would
  // compare unlike curves).
  nlohmann::json checkpoint_settings(const LearnContext& c, bool from_training) const {
    nlohmann::json settings = run_settings(c, effective_options(*this));
    if (from_training) settings["scored_on"] = "training starts no target used";
    return settings;
  }

  // The checkpoint after iteration k: the best model, named by its iteration and written before
  // the state that names it, then the state.
  void save_state(const LearnContext& c, int k, const DadRun& run) const {
    const std::string best_file = "best-" + std::to_string(run.best_iteration) + ".model";
    fs::create_directories(c.checkpoint_dir);
    if (!model_ownership().recognises(c.checkpoint_dir / best_file)) save_model(*run.best, c.checkpoint_dir / best_file);
    save_checkpoint(c.checkpoint_dir, k,
                    {{"run", checkpoint_settings(c, run.from_training)}, {"seed", c.seed}, {"regressor", c.regressor},
                     {"best_iteration", run.best_iteration}, {"best_model", best_file}, {"best_deviation", run.best_deviation},
                     {"corrections_kept", run.corrections}, {"corrections_filtered", run.filtered},
                     {"curve", curve_to_json(run.result.curve)}},
                    "dad.json", c, run.data, "DaD data after iteration " + std::to_string(k));
    remove_old_best_models(c.checkpoint_dir, best_file);
  }

  DadPlan make_plan(const std::string& features) const {
    DadPlan p;
    p.code = code_parts(params().choice("faithful"));
    p.windows = p.code.schedule ? kCodeWindows : static_cast<int>(params().integer("windows"));
    p.per_window = p.code.schedule ? kCodeRefits : static_cast<int>(params().integer("iterations"));
    p.aim = p.code.cost ? CorrectionTarget::dice
                        : params().choice("target") == "cup" ? CorrectionTarget::cup : CorrectionTarget::state;
    p.corrector = p.code.search ? "cmaes" : params().choice("corrector");
    p.search = {static_cast<int>(params().integer("corrector_iterations")), params().real("sigma0"),
                static_cast<int>(params().integer("population")), TrackerConfig{}.gain, 0, false};
    if (p.code.search) {
      p.search.evaluations = kCodeEvaluations;
      p.search.sigma0 = kCodeSigma0;
      p.search.random_start = true;
    }
    p.filter = !p.code.search && params().boolean("filter");
    p.keep_best = !p.code.schedule && params().boolean("keep_best");
    p.from_training = params().choice("starts") == "training";
    p.demos = static_cast<std::size_t>(params().integer("demos"));
    p.episodes = static_cast<int>(params().integer("episodes"));
    p.retry = expert_retries(params().choice("retry"), features);
    p.action_kind = feature_map(features).action_kind();
    return p;
  }

  static std::size_t rows_of(const std::vector<Episode>& data) {
    std::size_t rows = 0;
    for (const auto& e : data)
      for (std::size_t t = 0; t < e.size(); ++t) rows += is_row(e, t);
    return rows;
  }

  // The targets from training starts: the tracker's successful episodes (the recordings of
  // --demos, each start's choice moved into its frame and followed), without noise.
  std::vector<Episode> tracker_targets(const LearnContext& c, const DadPlan& plan, std::string& followed) const {
    ExpertConfig expert = learner_expert_config("tracker", *this, c);
    expert.retry = plan.retry;
    RecordRequest request;
    request.episodes = plan.episodes;
    request.seed = c.seed;
    request.threads = c.threads;
    if (c.progress) request.progress = [&c](int done, int total) { c.progress({"targets", 0, 0, 0, 0, done, total, 0.0}); };
    std::vector<Episode> targets;
    for (auto& e : record_expert("tracker", expert, c.world, request, *c.cluster))
      if (e.outcome.realistic_success()) {
        e.name = "target_" + std::to_string(targets.size());
        targets.push_back(std::move(e));
      }
    if (targets.empty())
      throw InputError("dad: the tracker stacked from none of " + std::to_string(request.episodes) + " training starts");
    followed = followed_recordings(*expert.recordings);
    return targets;
  }

  // What a refit after iteration k learns from: the data, and with the code's duplicates every
  // correction once more for each refit since it was made.
  static std::vector<Episode> fit_data(const std::vector<Episode>& data, const DadPlan& plan, int k) {
    if (!plan.code.duplicates) return data;
    std::vector<Episode> out;
    for (const auto& e : data) {
      const int made = made_at(e);
      const int copies = made == 0 ? 1 : std::max(1, k - made + 1);
      for (int i = 0; i < copies; ++i) out.push_back(e);
    }
    return out;
  }

  // Farthest-point selection on first states (the paper started from "three very different"
  // demonstrations): the first demonstration, then repeatedly the one farthest from all chosen.
  static std::vector<Episode> pick_targets(const std::vector<Episode>& demos, std::size_t n, const CostConfig& cost) {
    if (demos.empty()) throw InputError("dad: no demonstrations to learn from");
    if (n == 0 || n >= demos.size()) return demos;
    std::vector<std::size_t> chosen{0};
    std::vector<double> gap(demos.size());
    for (std::size_t i = 0; i < demos.size(); ++i) gap[i] = tracking_distance_sq(demos[i].states[0], demos[0].states[0], cost);
    while (chosen.size() < n) {
      const auto next = static_cast<std::size_t>(std::max_element(gap.begin(), gap.end()) - gap.begin());
      chosen.push_back(next);
      for (std::size_t i = 0; i < demos.size(); ++i)
        gap[i] = std::min(gap[i], tracking_distance_sq(demos[i].states[0], demos[next].states[0], cost));
    }
    std::sort(chosen.begin(), chosen.end());
    std::vector<Episode> out;
    for (std::size_t i : chosen) out.push_back(demos[i]);
    return out;
  }

  // Rolls the policy out from every target's first state (or the fixed start) and cuts its
  // trajectory into windows: each starts from the policy's world at that step and aims at the
  // target's next states. With the code's schedule the rollout covers only the window's prefix
  // of the recording (window/windows of it) and is one window; with the code's labels every
  // step is a window of one.
  static std::vector<Task> policy_tasks(const Model& model, const std::vector<Episode>& targets, const DadPlan& plan,
                                        int window, const std::optional<State>& fixed_start, EnvPool& envs, int threads,
                                        std::vector<Episode>& rollouts) {
    std::vector<std::vector<Task>> per_demo(targets.size());
    rollouts.assign(targets.size(), Episode{});
    parallel_for(targets.size(), threads, [&](std::size_t d, int w) {
      DiceEnv& env = envs.at(w);
      const Episode& demo = targets[d];
      const std::size_t len = demo.size();
      const std::size_t steps =
          plan.code.schedule ? std::min(len - 1, len * static_cast<std::size_t>(window) / static_cast<std::size_t>(plan.windows))
                             : len - 1;
      if (steps == 0) return;
      const std::size_t width =
          plan.code.label ? 1
          : plan.code.schedule
              ? steps
              : static_cast<std::size_t>(std::max(1.0, std::ceil(static_cast<double>(len) * window / plan.windows)));
      RolloutOptions options;
      options.max_steps = steps;
      options.before_step = [&](const DiceEnv& at, std::size_t t) {
        if (t % width != 0 || t >= steps) return;
        Task task{d, t, {at.snapshot(), {}, {}, plan.aim, {}, {}, plan.action_kind}};
        for (std::size_t j = t + 1; j < len && j <= t + width; ++j) {
          task.problem.target.push_back(demo.states[j]);
          task.problem.reference.push_back(demo.states[j - 1]);
          // A target recorded in joint torques holds no cup actions for the feedback law.
          const Action& recorded = demo.actions[j - 1];
          task.problem.reference_actions.push_back(recorded.kind() == ActionKind::cup
                                                       ? recorded
                                                       : cup_action_between(demo.states[j - 1], demo.states[j], at.config()));
        }
        per_demo[d].push_back(std::move(task));
      };
      const std::shared_ptr<const Model> borrowed(&model, [](const Model*) {});  // for this rollout
      ModelPolicy own(borrowed);
      CodeUnitsPolicy code(borrowed);
      Policy& policy = plan.code.units ? static_cast<Policy&>(code) : own;
      const State& start = fixed_start ? *fixed_start : demo.states[0];
      rollouts[d] = rollout(env, policy, start, demo.seed, StepSource::policy, options);
      const std::vector<Action>& actions = rollouts[d].actions;
      // The policy's own actions, zero past its episode's end (no velocity change; in joint
      // torques, none: the arm sags, which a correction then beats).
      for (auto& task : per_demo[d])
        for (std::size_t j = 0; j < task.problem.target.size(); ++j)
          task.problem.warm.push_back(task.t + j < actions.size() ? actions[task.t + j] : Action::zeros(plan.action_kind));
    });
    std::vector<Task> tasks;
    for (auto& v : per_demo)
      for (auto& t : v) tasks.push_back(std::move(t));
    return tasks;
  }

  // One-step corrections of iteration k as one episode per rollout: the states the policy
  // visited from its start, each labelled with the action the corrector found there (as DAgger
  // labels a rollout), so every feature map sees them in their episode.
  static std::vector<Episode> step_corrections(const std::vector<Task>& tasks, const std::vector<Correction>& fixes,
                                               const std::vector<Episode>& targets, int k) {
    std::vector<Episode> out;
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      if (i == 0 || tasks[i].demo != tasks[i - 1].demo) {
        const Episode& demo = targets[tasks[i].demo];
        Episode e;
        e.name = "dad_" + std::to_string(k) + "_" + demo.name + "_steps";
        e.seed = demo.seed;
        e.origin = std::string(kMadeAt) + std::to_string(k) + ": one-step corrections of a rollout towards " + demo.name;
        out.push_back(std::move(e));
      }
      Episode& e = out.back();
      e.states.push_back(fixes[i].states.front());
      e.actions.push_back(fixes[i].actions.front());
      e.sources.push_back(StepSource::correction);
      e.outcome.steps = static_cast<int>(e.states.size());
    }
    return out;
  }

  static std::string pack_correction(const Correction& fix) {
    Packer p;
    p.put_vector(fix.states).put_vector(fix.actions).put_vector(fix.links).put(fix.cost).put(fix.warm_cost).put(fix.evaluations);
    return p.take();
  }

  static Correction unpack_correction(std::string_view bytes) {
    Unpacker u(bytes, "correction");
    Correction fix;
    fix.states = u.get_vector<State>();
    fix.actions = u.get_vector<Action>();
    fix.links = u.get_vector<ArmLinks>();
    fix.cost = u.get<double>();
    fix.warm_cost = u.get<double>();
    fix.evaluations = u.get<int>();
    return fix;
  }

  // A window's correction; with `before`, after the rollout's first t steps (history, not rows).
  static Episode as_episode(const Correction& fix, const Episode& demo, std::size_t t, int iteration, const Episode* before) {
    Episode e;
    e.name = "dad_" + std::to_string(iteration) + "_" + demo.name + "_" + std::to_string(t);
    e.seed = demo.seed;
    e.origin = std::string(kMadeAt) + std::to_string(iteration) + ": correction of " + demo.name + " from step " + std::to_string(t);
    const auto cut = static_cast<std::ptrdiff_t>(t);
    if (before) {
      e.states.assign(before->states.begin(), before->states.begin() + cut);
      e.actions.assign(before->actions.begin(), before->actions.begin() + cut);
      e.sources.assign(t, StepSource::policy);
      if (!fix.links.empty()) e.links.assign(before->links.begin(), before->links.begin() + cut);
    }
    e.links.insert(e.links.end(), fix.links.begin(), fix.links.end());
    e.states.insert(e.states.end(), fix.states.begin(), fix.states.end());
    e.actions.insert(e.actions.end(), fix.actions.begin(), fix.actions.end());
    e.sources.resize(e.states.size(), StepSource::correction);
    e.outcome.steps = static_cast<int>(e.states.size());
    return e;
  }
};

}  // namespace

void register_dad(LearnerRegistry& r) {
  r.add({"dad", "DaD with windowed annealing: corrections towards the demonstrations, found in the simulator",
         Dad::schema(), [](std::string n, Params p) { return std::make_unique<Dad>(std::move(n), std::move(p)); }, true,
         "state", true});
}

}  // namespace dicestack
