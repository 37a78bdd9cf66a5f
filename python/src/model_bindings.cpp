// Models (load, predict, save), the policy a model gives (it keeps its episode's history for the
// feature map), the automatic experts, and train() / evaluate() (with its report page) /
// leaderboard() as the command line runs them, with a progress bar and Ctrl-C (LongCall).
#include <cmath>
#include <memory>
#include <optional>

#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <dicestack/core/estimator.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/experiments/report.hpp>
#include <dicestack/experiments/results_page.hpp>
#include <dicestack/experiments/train.hpp>
#include <dicestack/regressors/model.hpp>

#include "bindings.hpp"
#include "convert.hpp"
#include "demos.hpp"
#include "errors.hpp"
#include "long_call.hpp"

namespace dicestack::python {
namespace {

/// A model as Python holds it: where it lives on disk (if anywhere) and how it was trained.
struct PyModel {
  std::shared_ptr<Model> model;
  std::string path;          ///< the file it was loaded from or last saved to; empty: in memory
  std::optional<py::dict> training;  ///< train()'s report, for models made by train()
};

/// A model acting step by step: keeps the states of its episode for the feature map.
class PyPolicy {
 public:
  explicit PyPolicy(std::shared_ptr<const Model> model) : model_(std::move(model)) {}
  void reset() {
    states_.clear();
    links_.clear();
  }
  Action act(const py::handle& observation, const py::handle& pending, const py::handle& unseen, const py::handle& angles,
             const py::handle& rates) {
    const auto ahead = actions_from(pending, "pending");
    const auto since = actions_from(unseen, "unseen");
    const bool reads_links = model_->features().reads_links();
    if (reads_links && (angles.is_none() || rates.is_none()))
      throw py::value_error("feature map \"" + model_->features().name() +
                            "\" reads the arm's links: give link_angles and link_rates (the arm's info[\"link_angles\"], "
                            "info[\"link_rates\"])");
    State state = state_from(observation, "observation");
    if (reads_links) {
      const auto a = vector_from(angles, 3, "link_angles");
      const auto r = vector_from(rates, 3, "link_rates");
      links_.push_back({{a[0], a[1], a[2]}, {r[0], r[1], r[2]}});
    }
    states_.push_back(state);
    // The world's applied actions are not known here; no built-in feature map reads them.
    return model_->act(History{states_, {}, ahead, since, links_});
  }
  std::size_t t() const { return states_.empty() ? 0 : states_.size() - 1; }

 private:
  // None, or (N, 3) finite actions.
  static std::vector<Action> actions_from(const py::handle& rows, const char* what) {
    if (rows.is_none()) return {};
    auto actions = dicestack::python::actions_from(rows, what);
    for (std::size_t i = 0; i < actions.size(); ++i)
      for (std::size_t k = 0; k < kActionDim; ++k)
        if (!std::isfinite(actions[i][k]))
          throw py::value_error(std::string(what) + "[" + std::to_string(i) + "][" + std::to_string(k) +
                                "] must be finite, got " + std::to_string(actions[i][k]));
    return actions;
  }

  std::shared_ptr<const Model> model_;
  std::vector<State> states_;
  std::vector<ArmLinks> links_;  // with each state, for a map that reads them
};

// Policy.act and Policy.__call__: the action as a NumPy array of its size.
py::array_t<double> act_as_array(PyPolicy& p, const py::handle& obs, const py::handle& pending, const py::handle& unseen,
                                 const py::handle& angles, const py::handle& rates) {
  const Action a = p.act(obs, pending, unseen, angles, rates);
  return to_array(std::span<const double>(a.begin(), a.end()));
}

/// Demonstrations given as a name or folder ("builtin", "human", a path) or as episodes.
std::vector<Episode> demos_from(const py::handle& demos, const WorldConfig& world, std::string* name) {
  if (py::isinstance<py::str>(demos)) {
    const std::string spec = demos.cast<std::string>();
    std::filesystem::path dir;
    {
      py::gil_scoped_release nogil;
      dir = resolve_demo_set(spec, world);
    }
    if (name) *name = dir.string();
    return reading(dir, [&] { return read_demo_set(dir).episodes; });
  }
  if (name) *name = "<episodes from Python>";
  return episodes_from(demos.cast<py::iterable>());
}

/// An automatic expert acting on a Python environment; restarts (seeded with the episode's seed)
/// whenever it meets a new episode.
class PyExpert {
 public:
  /// `demos` (None, or as demos_from takes them) are the recordings "tracker" follows, ranked in
  /// `world` with `seed`, with the tracker_config of `preset` and `settings` ("NAME=VALUE"); other
  /// experts read none of them. `retry`: ExpertConfig::retry.
  PyExpert(const std::string& name, const py::handle& demos, const WorldConfig& world, std::uint64_t seed, bool retry,
           const std::string& preset, const std::vector<std::string>& settings) {
    ExpertConfig config;
    config.retry = retry;
    if (name != "tracker" && (preset != "plain" || !settings.empty()))
      throw py::value_error("expert \"" + name + "\" has no tracker settings (preset= and settings= set \"tracker\")");
    const TrackerConfig tracker = tracker_config(preset, settings);  // a bad one is refused before any work
    if (!demos.is_none()) {
      if (name != "tracker")
        throw py::value_error("expert \"" + name + "\" reads no demonstrations (demos= is the recordings of \"tracker\")");
      const std::vector<Episode> episodes = demos_from(demos, world, nullptr);
      py::gil_scoped_release nogil;
      config.recordings = make_recordings(episodes, world, tracker, seed);
    }
    expert_ = make_expert(name, config);
  }
  Action act(EnvCore& core) {
    if (world_hash_ && *world_hash_ != core.world_hash())
      throw py::value_error("expert \"" + expert_->name() +
                            "\" acts in the world of the first environment it was given; make one expert per world");
    if (&core != env_ || core.episodes() != episodes_ || core.env().t() == 0) {
      expert_->reset(core.episode_seed());
      env_ = &core;
      episodes_ = core.episodes();
      world_hash_ = core.world_hash();
    }
    return expert_->act(core.env(), core.pending());
  }
  std::string name() const { return expert_->name(); }

 private:
  std::unique_ptr<Expert> expert_;
  const EnvCore* env_ = nullptr;  // identity only, never dereferenced
  std::uint64_t episodes_ = 0;
  std::optional<std::uint64_t> world_hash_;
};

py::dict string_map(const std::map<std::string, std::string>& values) {
  py::dict d;
  for (const auto& [k, v] : values) d[py::str(k)] = v;
  return d;
}

/// Refuses a user's file at a model's path, and at its pickle's when the regressor pickles, before any work.
void check_model_replaceable(const std::filesystem::path& out, const std::string& regressor,
                             const std::vector<std::string>& sets) {
  check_replaceable(out, model_ownership());
  if (dynamic_cast<const PickledRegressor*>(RegressorRegistry::global().create(regressor, sets).get()))
    check_replaceable(pickle_path(out), pickle_ownership(out));
}

PyModel train(const WorldConfig& world, const py::handle& demos, const std::string& regressor,
              const std::vector<std::string>& sets, const std::string& learner, const std::vector<std::string>& options,
              const std::string& features, const std::string& split, const py::handle& seed, const py::handle& threads,
              const std::string& out, py::object bar) {
  if (!out.empty()) check_model_replaceable(out, regressor, sets);
  TrainRequest request;
  request.world = world;
  request.demos = demos_from(demos, world, &request.demos_name);
  request.regressor = regressor;
  request.regressor_sets = sets;
  request.learner = learner;
  request.learner_options = options;
  request.features = features;
  request.split = split;
  request.seed = seed_from(seed).value_or(0);
  request.threads = threads_from(threads);
  LongCall call(std::move(bar));
  request.progress = [&](const Progress& p) {
    call.poll(p.fraction, progress_text(learner + " " + regressor, p));
  };
  std::optional<TrainReport> report;
  {
    py::gil_scoped_release nogil;
    report = train_model(request);
    if (!out.empty()) save_model(*report->result.model, out);
  }
  py::dict training;
  training["learner"] = learner;
  training["features"] = report->features;
  training["seconds"] = report->seconds;
  if (report->score) training["train_error"] = report->score->train_error;
  if (report->score && report->score->test_error) training["test_error"] = *report->score->test_error;
  return {report->result.model, out, training};
}

std::string evaluate_model(const PyModel& m, const WorldConfig& world, int episodes, const py::handle& seed,
                           const py::handle& threads, const std::string& push, const py::handle& demos, py::object bar,
                           const Perturbation& perturbation, const std::string& perturb, const std::filesystem::path& report,
                           const std::string& estimator) {
  if (episodes < 1) throw py::value_error("episodes must be at least 1, got " + std::to_string(episodes));
  const std::string behind = estimator_for(estimator, *m.model);  // before any work
  const EstimatorConfig shown = estimator_config(behind);
  const EvaluationRun run{m.path.empty() ? "<in memory>" : m.path, seed_from(seed).value_or(0), push,
                          perturbation.nominal() ? "none" : perturb, start_distribution_name(world), behind};
  const InitialPush initial_push = initial_push_from(push);
  const int t = threads_from(threads);
  if (!report.empty()) check_report_replaceable(report);  // before any work, as `evaluate --report`
  std::optional<std::vector<Episode>> demo_episodes;
  if (!demos.is_none()) demo_episodes = demos_from(demos, world, nullptr);
  std::shared_ptr<const Model> model = m.model;
  check_map_world(model->features(), world);
  if (demo_episodes && model->features().action_kind() == ActionKind::joint_torque)
    throw py::value_error("demos: a policy in joint torques cannot be scored on recordings of the cup's actions");
  LongCall call(std::move(bar));
  py::gil_scoped_release nogil;
  std::vector<Episode> rollouts;
  std::vector<EpisodeResult> results;
  EvalRequest request;
  request.episodes = episodes;
  request.seed = run.seed;
  request.threads = t;
  request.push = initial_push;
  request.perturbation = perturbation;
  request.estimator = shown;
  request.actions = model->features().action_kind();
  request.rollouts = report.empty() ? nullptr : &rollouts;  // the report's previews and per-episode results
  request.results = report.empty() ? nullptr : &results;
  request.progress = [&](int finished, int of) {
    call.poll(static_cast<double>(finished) / of, "evaluate: " + std::to_string(finished) + "/" + std::to_string(of) + " rollouts");
  };
  const EvalStats stats = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, world, request);
  std::optional<Score> errors;
  if (demo_episodes) errors = score(*model, DemoSplit(*demo_episodes, "episodes"));
  if (!report.empty())
    write_report_folder(evaluation_board(run, *model, stats, results, rollouts, world, errors ? &*errors : nullptr), report);
  return evaluation_json(run, *model, stats, errors ? &*errors : nullptr);
}

/// The leaderboard's json table (its rows are what Python returns); written to `out` if given.
std::string leaderboard(const WorldConfig& world, const std::string& demos, const std::vector<std::string>& regressors,
                        const std::vector<std::string>& learners, const std::vector<std::string>& options,
                        const std::vector<std::string>& baselines, const std::vector<std::string>& features,
                        const std::string& profile, const std::string& split, int episodes, int seeds,
                        const py::handle& seed, const py::handle& threads, const std::string& out,
                        const std::string& format, py::object bar, const std::string& perturb, const std::string& estimator,
                        const std::string& controller) {
  if (!estimator.empty()) estimator_config(estimator);  // a bad name is refused before any work
  LeaderboardRequest request;
  request.controller = controller_from(controller);
  request.world = world;
  request.regressors = regressors;
  request.learners = learners;
  request.options = options;
  request.baselines = baselines;
  request.features = features;
  request.profile = profile;
  request.split = split;
  request.episodes = episodes;
  request.seeds = seeds;
  request.seed = seed_from(seed).value_or(0);
  request.threads = threads_from(threads);
  request.out = out;
  request.format = format;
  request.perturb = perturb;
  request.estimator = estimator;
  LongCall call(std::move(bar));
  py::gil_scoped_release nogil;
  request.demos = resolve_demo_set(demos, world);
  const Leaderboard board = reading(request.demos, [&] {
    return run_leaderboard(request, [&](const LeaderboardProgress& p) { call.poll(p.fraction, p.text); });
  });
  if (!out.empty()) write_leaderboard(board, format, out);
  return render_leaderboard(board, "json");
}

}  // namespace

void bind_models(py::module_& m) {
  py::class_<PyPolicy>(m, "Policy", "A model acting step by step; keeps its episode's states for the feature map")
      .def(
          "reset",
          [](PyPolicy& p, const py::object& seed) {
            (void)seed_from(seed);  // checked like every seed; a model's policy draws no random numbers
            p.reset();
          },
          py::arg("seed") = py::none(), "Starts a new episode")
      .def(
          "act",
          &act_as_array, py::arg("observation"), py::arg("pending") = py::none(), py::arg("unseen") = py::none(),
          py::arg("link_angles") = py::none(), py::arg("link_rates") = py::none(),
          "The action after this observation: (dvx, dvy, dw), or a torque map's four joint torques. Under delays, "
          "an \"/ahead\" map also reads the environment's pending and unseen actions (DiceStackEnv.pending, "
          ".unseen); a map that reads the arm's links takes info[\"link_angles\"] and info[\"link_rates\"]")
      .def(
          "__call__",
          &act_as_array, py::arg("observation"), py::arg("pending") = py::none(), py::arg("unseen") = py::none(),
          py::arg("link_angles") = py::none(), py::arg("link_rates") = py::none())
      .def_property_readonly("t", &PyPolicy::t);

  py::class_<PyModel>(m, "Model", "A trained model: a feature map, a regressor and their standardisers")
      .def("predict", [](const PyModel& pm, const py::handle& x) {
             const Matrix rows = matrix_from(x, pm.model->features().width(), "X");
             return to_array(pm.model->predict(rows));
           }, py::arg("X"),
           "The regressor's answers (N x 3; N x 4 for a /torque or /osc map) for rows of the model's feature map (N x input_dim): actions, or the cup "
           "velocities to set for a '/velocity' map (its policy acts with their difference from the cup's velocity), or "
           "the cup poses to servo to for a '/position' or '/osc' map (x measured from the start's mean die x for an '@dice' map; an "
           "'/osc' map's fourth answer is the posture's acceleration, and its policy turns the four into the arm's joint torques)")
      .def("policy", [](const PyModel& pm) { return PyPolicy(pm.model); }, "A fresh policy acting with this model")
      .def("save", [](PyModel& pm, const std::filesystem::path& path) {
             save_model(*pm.model, path);
             pm.path = path.string();
           }, py::arg("path"), "Writes the model file (never over a file that is not a dicestack model)")
      .def_property_readonly("features", [](const PyModel& pm) { return pm.model->features().name(); })
      .def_property_readonly("features_version", [](const PyModel& pm) { return pm.model->features().version(); })
      .def_property_readonly("input_dim", [](const PyModel& pm) { return pm.model->features().width(); })
      .def_property_readonly("input_names", [](const PyModel& pm) { return pm.model->features().column_names(); })
      .def_property_readonly("regressor", [](const PyModel& pm) { return pm.model->regressor().name(); })
      .def_property_readonly("params", [](const PyModel& pm) {
             py::dict d;
             for (const auto& [k, v] : pm.model->regressor().params().as_text()) d[py::str(k)] = v;
             return d;
           })
      .def_property_readonly("record", [](const PyModel& pm) { return string_map(pm.model->record); })
      .def_property_readonly("path", [](const PyModel& pm) { return pm.path.empty() ? py::object(py::none()) : py::str(pm.path); })
      .def_property_readonly("training", [](const PyModel& pm) { return pm.training ? py::object(*pm.training) : py::none(); });

  m.def("load_model", [](const std::filesystem::path& path, bool allow_pickle) {
          const PickleLoader pickles = allow_pickle ? python_pickle_loader() : PickleLoader();
          auto model = reading(path, [&] { return load_model(path, RegressorRegistry::global(), pickles); });
          return PyModel{std::make_shared<Model>(std::move(model)), path.string(), std::nullopt};
        }, py::arg("path"), py::arg("allow_pickle"));

  py::class_<PyExpert>(m, "Expert", "An automatic expert (\"scripted\", \"mpc\" or \"tracker\") acting on an environment")
      .def(py::init<const std::string&, const py::handle&, const WorldConfig&, std::uint64_t, bool, const std::string&,
                    const std::vector<std::string>&>(),
           py::arg("name"), py::arg("demos"), py::arg("world"), py::arg("seed"), py::arg("retry"), py::arg("preset") = "plain",
           py::arg("settings") = std::vector<std::string>{})
      .def("act", [](PyExpert& e, const py::handle& env) { return to_array(e.act(env_core(env))); }, py::arg("env"))
      .def("__call__", [](PyExpert& e, const py::handle& env) { return to_array(e.act(env_core(env))); }, py::arg("env"))
      .def_property_readonly("name", &PyExpert::name);
  m.def("expert_names", [] {
    std::vector<std::string> names;
    for (const auto& e : expert_list()) names.push_back(e.name);
    return names;
  });

  m.def("train", &train, py::arg("world"), py::arg("demos"), py::arg("regressor"), py::arg("sets"), py::arg("learner"),
        py::arg("options"), py::arg("features"), py::arg("split"), py::arg("seed"), py::arg("threads"), py::arg("out"),
        py::arg("bar"));
  m.def("evaluate", &evaluate_model, py::arg("model"), py::arg("world"), py::arg("episodes"), py::arg("seed"),
        py::arg("threads"), py::arg("initial_push"), py::arg("demos"), py::arg("bar"),
        py::arg("perturbation") = Perturbation{}, py::arg("perturb") = "none",
        py::arg("report") = std::filesystem::path(), py::arg("estimator") = "");
  m.def(
      "leaderboard_formats",
      [] {
        std::vector<std::pair<std::string, std::string>> out;  // (suffix, name), in --format's order
        for (const LeaderboardFormat& f : leaderboard_formats()) out.emplace_back(f.suffix, f.name);
        return out;
      },
      "The leaderboard's formats as (file suffix, format name) pairs");
  m.def("leaderboard", &leaderboard, py::arg("world"), py::arg("demos"), py::arg("regressors"), py::arg("learners"),
        py::arg("options"), py::arg("baselines"), py::arg("features"), py::arg("profile"), py::arg("split"),
        py::arg("episodes"), py::arg("seeds"), py::arg("seed"), py::arg("threads"), py::arg("out"), py::arg("format"),
        py::arg("bar"), py::arg("perturb") = "none", py::arg("estimator") = "", py::arg("controller") = "cup");
}

}  // namespace dicestack::python
