#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/learners/corrector.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>

#include "checkpoint.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;

// One window to correct: where in which demonstration, and the problem the corrector solves.
struct Task {
  std::size_t demo = 0;
  std::size_t t = 0;
  CorrectionProblem problem;
};

// DaD with windowed annealing (paper VI-E, DESIGN "Learners"): roll the policy out from each
// demonstration's first state; at every w-th step, from the policy's own drifted world, find
// the next w actions that bring the simulated cup back onto the demonstration's cup path (or,
// with target=state, all simulated states onto the demonstration's: eq. 11 as written);
// add those (state, action) pairs to the data once (eq. 10); refit. Windows grow from 1/10 of
// the demonstration to all of it, with a few iterations each.
class Dad final : public Learner {
 public:
  using Learner::Learner;

  LearnResult learn(const LearnContext& c) const override {
    // Corrections are windows cut from the middle of a drifted episode: a map that reads the
    // step index, the start or the previous state would see them out of their episode.
    if (c.features != "state")
      throw ConfigError("dad: feature map \"" + c.features + "\" reads more than the current state, and DaD's "
                        "corrections are windows without their episode; use --features state");
    const int windows = static_cast<int>(params().integer("windows"));
    const int per_window = static_cast<int>(params().integer("iterations"));
    const int total = windows * per_window;
    const std::vector<Episode> targets = pick_targets(c.demos, static_cast<std::size_t>(params().integer("demos")), c.world.cost);
    // Long recordings must not be cut by the time limit.
    WorldConfig world = c.world;
    for (const auto& d : targets) world.episode.max_steps = std::max(world.episode.max_steps, static_cast<int>(d.size()) + 1);

    std::vector<Episode> data = targets;
    LearnResult result;
    std::shared_ptr<Model> best;
    double best_deviation = 0.0;
    int best_iteration = 0, first = 1;
    std::size_t corrections = 0, filtered = 0;
    if (const auto state = load_checkpoint_state(c, "dad.json", run_settings(c, params()))) {
      first = state->iteration() + 1;
      data = state->data();
      result.curve = state->curve();
      best_iteration = static_cast<int>(state->integer("best_iteration", 0, state->iteration()));
      best_deviation = state->number("best_deviation");
      best = std::make_shared<Model>(load_model(c.checkpoint_dir / state->file("best_model"), *c.registry));
      corrections = static_cast<std::size_t>(state->integer("corrections_kept", 0, INT64_MAX));
      filtered = static_cast<std::size_t>(state->integer("corrections_filtered", 0, INT64_MAX));
    }
    std::shared_ptr<Model> model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(first - 1)));
    if (first == 1) {
      result.curve.push_back(measure_policy(model, c, targets, 0, rows_of(data)));
      best = model;
      best_deviation = result.curve.back().deviation;
    }

    EnvPool envs(world, c.threads);
    const auto corrector = make_corrector(params().choice("corrector"),
                                          {static_cast<int>(params().integer("corrector_iterations")), params().real("sigma0"),
                                           static_cast<int>(params().integer("population")), TrackerConfig{}.gain});
    for (int k = first; k <= total; ++k) {
      const int window = (k - 1) / per_window + 1;
      auto report = [&](const char* phase, int done, int of) {
        if (c.progress)
          c.progress({phase, k, total, window, windows, done, of, (k - 1 + (of ? static_cast<double>(done) / of : 0.0)) / total});
      };
      report("rollouts", 0, 0);
      const std::vector<Task> tasks = policy_windows(*model, targets, window, windows, aim(), envs, c.threads);

      // Every rank cut the same windows (the rollouts are deterministic); the corrections, the
      // heavy part, are dealt among the ranks by window length and gathered in index order.
      std::atomic<int> finished{0};
      const int ranks = c.cluster->size();
      const std::uint64_t round_seed = derive_seed(c.seed, 1000003u + static_cast<std::uint64_t>(k));
      std::vector<double> cost(tasks.size());
      for (std::size_t i = 0; i < tasks.size(); ++i) cost[i] = static_cast<double>(tasks[i].problem.target.size());
      const std::vector<Correction> fixes = distributed_map<Correction>(
          *c.cluster, tasks.size(), c.threads,
          [&](std::size_t i, int w) {
            Correction fix = corrector->correct(envs.at(w), tasks[i].problem, derive_seed(round_seed, i));
            const int done = std::min(static_cast<int>(tasks.size()), ++finished * ranks);
            if (w == 0) report("corrections", done, static_cast<int>(tasks.size()));
            return fix;
          },
          pack_correction, unpack_correction, ranks > 1 ? cost : std::vector<double>{});

      for (std::size_t i = 0; i < tasks.size(); ++i) {
        if (params().boolean("filter") && !(fixes[i].cost < fixes[i].warm_cost)) {
          ++filtered;
          continue;
        }
        data.push_back(as_episode(fixes[i], targets[tasks[i].demo], tasks[i].t, k));
        ++corrections;
      }
      report("fit", 0, 1);
      model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(k)));
      CurvePoint point = measure_policy(model, c, targets, k, rows_of(data));
      point.window = window;
      result.curve.push_back(point);
      if (point.deviation < best_deviation) {
        best = model;
        best_deviation = point.deviation;
        best_iteration = k;
      }
      if (!c.checkpoint_dir.empty() && c.cluster->is_root()) {
        // The best model is named by its iteration and written before the state that names it.
        const std::string best_file = "best-" + std::to_string(best_iteration) + ".model";
        fs::create_directories(c.checkpoint_dir);
        if (!model_ownership().recognises(c.checkpoint_dir / best_file)) save_model(*best, c.checkpoint_dir / best_file);
        save_checkpoint(c.checkpoint_dir, k,
                        {{"run", run_settings(c, params())}, {"seed", c.seed}, {"regressor", c.regressor}, {"best_iteration", best_iteration},
                         {"best_model", best_file}, {"best_deviation", best_deviation}, {"corrections_kept", corrections},
                         {"corrections_filtered", filtered}, {"curve", curve_to_json(result.curve)}},
                        "dad.json", c, data, "DaD data after iteration " + std::to_string(k));
        remove_old_best_models(c.checkpoint_dir, best_file);
      }
    }
    const std::shared_ptr<Model> chosen = params().boolean("keep_best") ? best : model;
    chosen->record["learner"] = "dad";
    chosen->record["dad_iteration"] = std::to_string(params().boolean("keep_best") ? best_iteration : total);
    chosen->record["dad_targets"] = std::to_string(targets.size());
    chosen->record["dad_scored_on"] = c.held_out.empty() ? "targets" : std::to_string(c.held_out.size()) + " held-out demonstrations";
    chosen->record["dad_corrections_kept"] = std::to_string(corrections);
    chosen->record["dad_corrections_filtered"] = std::to_string(filtered);
    result.model = chosen;
    return result;
  }

  static std::vector<ParamSpec> schema() {
    return {{"windows", ParamType::integer, "10", 1, 1000, "window sizes: k/windows of each demonstration, k = 1..windows", {}},
            {"iterations", ParamType::integer, "3", 1, 1000, "iterations per window", {}},
            {"corrector", ParamType::choice, "cmaes", 0, 0,
             "how each window's actions are found: an optimiser, or track (the tracker's feedback law, no search)",
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
            {"keep_best", ParamType::boolean, "true", 0, 1, "return the iteration's policy that follows the held-out demonstrations best", {}}};
  }

 private:
  static std::size_t rows_of(const std::vector<Episode>& data) {
    std::size_t rows = 0;
    for (const auto& e : data) rows += e.size();
    return rows;
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

  // Rolls the policy out from every target's first state and cuts its trajectory into windows
  // of w steps: each starts from the policy's world at that step, aims at the target's states.
  CorrectionTarget aim() const { return params().choice("target") == "cup" ? CorrectionTarget::cup : CorrectionTarget::state; }

  static std::vector<Task> policy_windows(const Model& model, const std::vector<Episode>& targets, int window, int windows,
                                          CorrectionTarget aim, EnvPool& envs, int threads) {
    std::vector<std::vector<Task>> per_demo(targets.size());
    parallel_for(targets.size(), threads, [&](std::size_t d, int w) {
      DiceEnv& env = envs.at(w);
      const Episode& demo = targets[d];
      const std::size_t len = demo.size();
      const auto width = static_cast<std::size_t>(std::max(1.0, std::ceil(static_cast<double>(len) * window / windows)));
      RolloutOptions options;
      options.max_steps = len - 1;
      options.before_step = [&](const DiceEnv& at, std::size_t t) {
        if (t % width != 0) return;
        Task task{d, t, {at.snapshot(), {}, {}, aim, {}, {}}};
        for (std::size_t j = t + 1; j < len && j <= t + width; ++j) {
          task.problem.target.push_back(demo.states[j]);
          task.problem.reference.push_back(demo.states[j - 1]);
          task.problem.reference_actions.push_back(demo.actions[j - 1]);
        }
        per_demo[d].push_back(std::move(task));
      };
      ModelPolicy policy(std::shared_ptr<const Model>(&model, [](const Model*) {}));  // borrowed for this rollout
      const std::vector<Action> actions =
          len > 1 ? rollout(env, policy, demo.states[0], demo.seed, StepSource::policy, options).actions
                  : std::vector<Action>{};
      for (auto& task : per_demo[d])  // the policy's own actions, held at zero past its episode's end
        for (std::size_t j = 0; j < task.problem.target.size(); ++j)
          task.problem.warm.push_back(task.t + j < actions.size() ? actions[task.t + j] : Action{0.0, 0.0, 0.0});
    });
    std::vector<Task> tasks;
    for (auto& v : per_demo)
      for (auto& t : v) tasks.push_back(std::move(t));
    return tasks;
  }

  static std::string pack_correction(const Correction& fix) {
    Packer p;
    p.put_vector(fix.states).put_vector(fix.actions).put(fix.cost).put(fix.warm_cost).put(fix.evaluations);
    return p.take();
  }

  static Correction unpack_correction(std::string_view bytes) {
    Unpacker u(bytes, "correction");
    Correction fix;
    fix.states = u.get_vector<State>();
    fix.actions = u.get_vector<Action>();
    fix.cost = u.get<double>();
    fix.warm_cost = u.get<double>();
    fix.evaluations = u.get<int>();
    return fix;
  }

  static Episode as_episode(const Correction& fix, const Episode& demo, std::size_t t, int iteration) {
    Episode e;
    e.name = "dad_" + std::to_string(iteration) + "_" + demo.name + "_" + std::to_string(t);
    e.seed = demo.seed;
    e.origin = "dad correction of " + demo.name + " from step " + std::to_string(t);
    e.states = fix.states;
    e.actions = fix.actions;
    e.sources.assign(e.states.size(), StepSource::correction);
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
