// Env (one environment), Snapshot (its exact, picklable copy) and VectorEnv (N environments
// stepped in C++ on all cores with the GIL released, autoreset on the next step).
#include <algorithm>
#include <atomic>
#include <optional>
#include <vector>

#include <pybind11/stl.h>

#include <dicestack/core/memory_budget.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/worker_pool.hpp>
#include <dicestack/core/render.hpp>

#include "bindings.hpp"
#include "convert.hpp"

namespace dicestack::python {
namespace {

/// An EnvSnapshot with the world it belongs to and the episode bookkeeping around it.
struct Snapshot {
  EnvSnapshot env;
  std::uint64_t world_hash = 0;
  std::uint64_t episode_seed = 0;
  std::optional<std::uint64_t> seed_base;
  std::uint64_t seed_count = 0;
};

constexpr int kSnapshotPickleVersion = 1;

Snapshot take_snapshot(EnvCore& core) {
  if (core.channelled())
    throw py::value_error("snapshot: this episode's actions or observations are perturbed; their delays and noise are "
                          "not in a snapshot, so it could not continue bit for bit");
  return {core.env().snapshot(), core.world_hash(), core.episode_seed(), core.seeds().base(), core.seeds().count()};
}

void restore_snapshot(EnvCore& core, const Snapshot& s) {
  if (core.channelled())
    throw py::value_error("restore: this episode's actions or observations are perturbed (delays and noise are not in a "
                          "snapshot); restore into an environment without actuation or sensing perturbations");
  if (s.world_hash != core.world_hash())
    throw py::value_error("snapshot was taken in another world (world config hash " + std::to_string(s.world_hash) +
                          ", this environment's " + std::to_string(core.world_hash()) + ")");
  core.env().restore(s.env);
  core.seeds().set(s.seed_base, s.seed_count);
  core.restored(s.episode_seed);
}

py::tuple snapshot_state(const Snapshot& s) {
  return py::make_tuple(kSnapshotPickleVersion, s.world_hash, py::bytes(to_bytes(s.env)), s.episode_seed,
                        s.seed_base ? py::object(py::int_(*s.seed_base)) : py::none(), s.seed_count);
}

Snapshot snapshot_from_state(const py::tuple& t) {
  if (t.size() != 6 || t[0].cast<int>() != kSnapshotPickleVersion)
    throw py::value_error("not a dicestack snapshot record (expected version " + std::to_string(kSnapshotPickleVersion) +
                          " with 6 fields)");
  Snapshot s;
  s.world_hash = t[1].cast<std::uint64_t>();
  s.env = env_snapshot_from_bytes(t[2].cast<std::string>());
  s.episode_seed = t[3].cast<std::uint64_t>();
  if (!t[4].is_none()) s.seed_base = t[4].cast<std::uint64_t>();
  s.seed_count = t[5].cast<std::uint64_t>();
  return s;
}

template <std::size_t N>
py::tuple bounds(const Box<N>& box) {
  return py::make_tuple(to_array(box.low), to_array(box.high));
}

py::tuple action_bounds(const EnvCore& core) {
  return core.controller() == ActionKind::cup ? bounds(core.env().action_space()) : bounds(core.env().torque_space());
}

// An arm's links and joints beside the 24 observed numbers, which a joint-torque policy needs
// (behind an estimator, the links of the state it shows).
py::dict with_arm(py::dict info, const EnvCore& core) {
  const World& w = core.env().world();
  if (w.config().embodiment != Embodiment::arm) return info;
  const ArmLinks links = core.shown_links();
  info["link_angles"] = to_array(links.angles);
  info["link_rates"] = to_array(links.rates);
  info["joint_torques"] = to_array(w.arm_step_torques());  // as demonstration sets keep them
  return info;
}

py::array_t<std::uint8_t> render_rgb(const EnvCore& core, double pixels_per_metre, bool hud) {
  const DiceEnv& env = core.env();
  RenderOptions options;
  options.pixels_per_metre = pixels_per_metre;
  options.show_hud = hud;
  const Image image = render_state(env.get_state(), env.config(), Hud{env.t(), env.outcome(), ""}, options);
  py::array_t<std::uint8_t> out({image.height, image.width, 3});
  std::uint8_t* p = out.mutable_data();
  for (std::size_t i = 0; i + 2 < image.bgr.size(); i += 3) {  // BGR -> RGB
    p[i] = image.bgr[i + 2];
    p[i + 1] = image.bgr[i + 1];
    p[i + 2] = image.bgr[i];
  }
  return out;
}

/// What one slot of the vector env produced in a step.
struct SlotResult {
  State observation{};
  double reward = 0.0;
  bool terminated = false;
  bool truncated = false;
  StepInfo info;
};

/// The arrays a vector reset or step returns: made on the calling thread (they are Python
/// objects) while the workers step, filled from the slots afterwards.
class BatchArrays {
 public:
  explicit BatchArrays(std::size_t n)
      : n_(n),
        observations_({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(kStateDim)}),
        rewards_(static_cast<py::ssize_t>(n)),
        terminated_(static_cast<py::ssize_t>(n)),
        truncated_(static_cast<py::ssize_t>(n)) {
    // Gymnasium's vector info: one array per key, and a "_key" mask of the environments that
    // report it (all of them, always).
    column("t", columns_.t);
    column("distance", columns_.distance);
    column("wall_contact_step", columns_.wall_contact_step);
    column("dice_in_cup", columns_.dice_in_cup);
    column("dice_in_cup_now", columns_.dice_in_cup_now);
    column("stacked", columns_.stacked);
    column("stacked_steps", columns_.stacked_steps);
    column("wall_contact", columns_.wall_contact);
    column("realistic_success", columns_.realistic_success);
  }

  void fill(const std::vector<SlotResult>& slots) {
    double* obs = observations_.mutable_data();
    for (std::size_t i = 0; i < n_; ++i) {
      const SlotResult& r = slots[i];
      obs = std::copy(r.observation.begin(), r.observation.end(), obs);
      rewards_.mutable_data()[i] = r.reward;
      terminated_.mutable_data()[i] = r.terminated;
      truncated_.mutable_data()[i] = r.truncated;
      columns_.t[i] = r.info.t;
      columns_.distance[i] = r.info.distance;
      columns_.wall_contact_step[i] = r.info.wall_contact_step;
      columns_.dice_in_cup[i] = r.info.outcome.dice_in_cup;
      columns_.dice_in_cup_now[i] = r.info.outcome.dice_in_cup_now;
      columns_.stacked[i] = r.info.outcome.stacked;
      columns_.stacked_steps[i] = r.info.outcome.stacked_steps;
      columns_.wall_contact[i] = r.info.outcome.wall_contact;
      columns_.realistic_success[i] = r.info.outcome.realistic_success();
    }
  }

  py::tuple reset_tuple() const { return py::make_tuple(observations_, infos_); }
  py::tuple step_tuple() const { return py::make_tuple(observations_, rewards_, terminated_, truncated_, infos_); }

 private:
  struct Columns {
    std::int64_t* t = nullptr;
    double* distance = nullptr;
    bool* wall_contact_step = nullptr;
    std::int64_t* dice_in_cup = nullptr;
    std::int64_t* dice_in_cup_now = nullptr;
    bool* stacked = nullptr;
    std::int64_t* stacked_steps = nullptr;
    bool* wall_contact = nullptr;
    bool* realistic_success = nullptr;
  };

  template <class T>
  void column(const char* key, T*& data) {
    py::array_t<T> values(static_cast<py::ssize_t>(n_));
    py::array_t<bool> mask(static_cast<py::ssize_t>(n_));
    std::fill_n(mask.mutable_data(), n_, true);
    data = values.mutable_data();
    infos_[key] = values;
    infos_[py::str(std::string("_") + key)] = mask;
  }

  std::size_t n_;
  py::array_t<double> observations_;
  py::array_t<double> rewards_;
  py::array_t<bool> terminated_, truncated_;
  py::dict infos_;
  Columns columns_;
};

/// N environments, autoreset "next-step" (Gymnasium 1.x's default): the step after an episode
/// ended resets that environment and returns its first observation with reward 0 and
/// terminated = truncated = False.
class VectorEnv {
 public:
  /// What one environment holds, with its share of the arrays a step returns: measured 107-114 KB
  /// of resident memory each after a reset and 3 steps of 1,000 and of 10,000 environments.
  static constexpr double kEnvironmentBytes = 120e3;

  VectorEnv(const WorldConfig& world, long long num_envs, int threads, const Perturbation& perturbation,
            const EstimatorConfig& estimator, ActionKind controller)
      : controller_(controller), pool_(pool_size(num_envs, threads, estimator)) {
    envs_.reserve(static_cast<std::size_t>(num_envs));
    validate(perturbation, world);
    for (long long i = 0; i < num_envs; ++i) envs_.emplace_back(world, perturbation, estimator, controller);
    done_.assign(envs_.size(), 0);
    slots_.resize(envs_.size());
  }

  std::size_t size() const { return envs_.size(); }
  /// Each environment's pending (or unseen) actions under its delays, as (d, 3) arrays ((d, 4)
  /// under joint_torque).
  py::list queues(bool pending) const {
    py::list out;
    for (const EnvCore& e : envs_) out.append(actions_to_array(pending ? e.pending() : e.unseen(), controller_));
    return out;
  }

  // The count checked before the pool's threads start: at least 1, and within memory with each
  // environment's estimator.
  static int pool_size(long long num_envs, int threads, const EstimatorConfig& estimator) {
    if (num_envs < 1) throw py::value_error("num_envs must be at least 1, got " + std::to_string(num_envs));
    require_memory("DiceStackVectorEnv", static_cast<std::uint64_t>(num_envs), kEnvironmentBytes + estimator_bytes(estimator),
                   "environments");
    return static_cast<int>(std::min<long long>(num_envs, resolve_threads(threads)));
  }

  py::tuple reset(const std::vector<std::optional<std::uint64_t>>& seeds) {
    if (seeds.size() != envs_.size())
      throw py::value_error("reset needs one seed (or None) per environment: " + std::to_string(envs_.size()) +
                            ", got " + std::to_string(seeds.size()));
    const BatchArrays out = run([&](std::size_t i) {
      SlotResult& r = slots_[i];
      r = SlotResult{};
      r.observation = envs_[i].reset(seeds[i]);
      r.info = envs_[i].info();
      done_[i] = 0;
    });
    return out.reset_tuple();
  }

  py::tuple step(const py::handle& action_rows) {
    const auto actions = actions_from(action_rows, "actions", controller_);
    if (actions.size() != envs_.size())
      throw py::value_error("actions must have shape (" + std::to_string(envs_.size()) + ", " +
                            std::to_string(action_dim(controller_)) + "), got " + std::to_string(actions.size()) + " rows");
    for (std::size_t i = 0; i < actions.size(); ++i) require_finite(actions[i], "action of environment " + std::to_string(i));
    const BatchArrays out = run([&](std::size_t i) {
      SlotResult& r = slots_[i];
      if (done_[i]) {
        r = SlotResult{};
        r.observation = envs_[i].reset(std::nullopt);
        r.info = envs_[i].info();
        done_[i] = 0;
        return;
      }
      const StepResult s = envs_[i].step(actions[i]);
      r = {s.observation, s.reward, s.terminated, s.truncated, s.info};
      done_[i] = s.terminated || s.truncated;
    });
    return out.step_tuple();
  }

 private:
  // Runs fn(i) for every environment on the pool's threads, without the GIL, while this thread
  // makes the arrays to return; one call at a time.
  template <class Fn>
  BatchArrays run(Fn&& fn) {
    if (busy_.exchange(true)) throw std::logic_error("DiceStackVectorEnv: reset or step called from two threads at once");
    struct Release {
      std::atomic<bool>& flag;
      ~Release() { flag = false; }
    } release{busy_};
    std::optional<BatchArrays> out;
    {
      std::optional<py::gil_scoped_release> nogil;
      pool_.run(envs_.size(), [&](std::size_t i, int) { fn(i); }, [&] {
        out.emplace(envs_.size());
        nogil.emplace();
      });
    }
    out->fill(slots_);
    return std::move(*out);
  }

  ActionKind controller_;
  std::vector<EnvCore> envs_;
  std::vector<char> done_;
  std::vector<SlotResult> slots_;
  std::atomic<bool> busy_{false};
  WorkerPool pool_;  // last: its threads stop before the environments go
};

}  // namespace

std::optional<std::uint64_t> seed_from(const py::handle& seed, const char* what) {
  if (seed.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(seed) || !PyIndex_Check(seed.ptr()))
    throw py::type_error(std::string(what) + " must be an int or None, got " + std::string(py::repr(seed)));
  const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(seed.ptr()));
  if (!index) throw py::error_already_set();
  const unsigned long long value = PyLong_AsUnsignedLongLong(index.ptr());
  if (value == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
    PyErr_Clear();
    throw py::value_error(std::string(what) + " must be a whole number in [0, 2^64 - 1], got " + std::string(py::repr(seed)));
  }
  return value;
}

int threads_from(const py::handle& threads) {
  if (threads.is_none()) return 0;
  if (!py::isinstance<py::int_>(threads) || py::isinstance<py::bool_>(threads))
    throw py::value_error("threads must be a whole number in [0, " + std::to_string(kMaxThreads) + "] or None, got " +
                          py::repr(threads).cast<std::string>());
  const py::int_ big(kMaxThreads);
  if (threads.attr("__gt__")(big).cast<bool>())
    throw py::value_error("threads must be in [0, " + std::to_string(kMaxThreads) + "] (0 or None: all cores), got " +
                          py::str(threads).cast<std::string>());
  const long long t = threads.cast<long long>();
  if (t < 0 || t > kMaxThreads)
    throw py::value_error("threads must be in [0, " + std::to_string(kMaxThreads) + "] (0 or None: all cores), got " +
                          std::to_string(t));
  return static_cast<int>(t);
}

py::dict info_dict(const StepInfo& i) {
  py::dict d;
  d["t"] = i.t;
  d["distance"] = i.distance;
  d["wall_contact_step"] = i.wall_contact_step;
  d["dice_in_cup"] = i.outcome.dice_in_cup;
  d["dice_in_cup_now"] = i.outcome.dice_in_cup_now;
  d["stacked"] = i.outcome.stacked;
  d["stacked_steps"] = i.outcome.stacked_steps;
  d["wall_contact"] = i.outcome.wall_contact;
  d["realistic_success"] = i.outcome.realistic_success();
  return d;
}

EnvCore& env_core(const py::handle& env) {
  if (py::isinstance<EnvCore>(env)) return env.cast<EnvCore&>();
  if (py::hasattr(env, "_env")) {
    const py::object inner = env.attr("_env");
    if (py::isinstance<EnvCore>(inner)) return inner.cast<EnvCore&>();  // kept alive by `env`
  }
  throw py::type_error("expected a dicestack.DiceStackEnv, got " + std::string(py::repr(env)));
}

namespace {

// The Env class: one environment.
void bind_env_core(py::module_& m) {
  py::class_<EnvCore>(m, "Env", "One dice-stacking environment (the core of dicestack.DiceStackEnv)")
      .def(py::init([](const WorldConfig& world, const Perturbation& perturbation, const std::string& estimator,
                       const std::string& controller) {
             return std::make_unique<EnvCore>(world, perturbation, estimator_config(estimator), controller_from(controller));
           }),
           py::arg("world"), py::arg("perturbation") = Perturbation{}, py::arg("estimator") = "none",
           py::arg("controller") = "cup")
      .def(
          "reset",
          [](EnvCore& core, const py::object& seed, const py::object& state, const std::optional<Perturbation>& p) {
            const auto s = seed_from(seed);
            const Perturbation* override = p ? &*p : nullptr;
            const State obs = state.is_none() ? core.reset(s, override)
                                              : core.reset_to(state_from(state, "options[\"state\"]"), s, override);
            return py::make_tuple(to_array(obs), with_arm(info_dict(core.info()), core));
          },
          py::arg("seed") = py::none(), py::arg("state") = py::none(), py::arg("perturbation") = py::none())
      .def_property_readonly("draw", [](const EnvCore& c) { return draw_to_json(c.draw(), c.controller()); })
      .def_property_readonly("perturbed", [](const EnvCore& c) { return c.draw().physics || c.draw().acts; })
      .def(
          "step",
          [](EnvCore& core, const py::handle& action) {
            const StepResult r = core.step(action_from(action, "action", core.controller()));
            return py::make_tuple(to_array(r.observation), r.reward, r.terminated, r.truncated, with_arm(info_dict(r.info), core));
          },
          py::arg("action"))
      .def("snapshot", &take_snapshot)
      .def("restore", &restore_snapshot, py::arg("snapshot"))
      .def("render", &render_rgb, py::arg("pixels_per_metre") = 100.0, py::arg("hud") = true)
      .def("observation_bounds", [](const EnvCore& c) { return bounds(c.env().observation_space()); })
      .def("action_bounds", &action_bounds)
      .def_property_readonly("controller", [](const EnvCore& c) { return std::string(action_kind_name(c.controller())); })
      .def_property_readonly("state", [](const EnvCore& c) { return to_array(c.env().get_state()); })
      .def_property_readonly("t", [](const EnvCore& c) { return c.env().t(); })
      .def_property_readonly("pending", [](const EnvCore& c) { return actions_to_array(c.pending(), c.controller()); })
      .def_property_readonly("unseen", [](const EnvCore& c) { return actions_to_array(c.unseen(), c.controller()); })
      .def_property_readonly("info", [](const EnvCore& c) { return info_dict(c.info()); })
      .def_property_readonly("world", [](const EnvCore& c) { return c.env().config(); })
      .def_property_readonly("world_hash", &EnvCore::world_hash)
      .def_property_readonly("episode_seed", &EnvCore::episode_seed);
}

// The VectorEnv class: N environments stepped together.
void bind_vector_env(py::module_& m) {
  py::class_<VectorEnv>(m, "VectorEnv", "N environments stepped in C++ (the core of dicestack.DiceStackVectorEnv)")
      .def(py::init([](const WorldConfig& world, long long num_envs, const py::object& threads, const Perturbation& perturbation,
                       const std::string& estimator, const std::string& controller) {
             const EstimatorConfig shown = estimator_config(estimator);  // before any environment is made
             return std::make_unique<VectorEnv>(world, num_envs, threads_from(threads), perturbation, shown,
                                                controller_from(controller));
           }),
           py::arg("world"), py::arg("num_envs"), py::arg("threads") = py::none(), py::arg("perturbation") = Perturbation{},
           py::arg("estimator") = "none", py::arg("controller") = "cup")
      .def("__len__", &VectorEnv::size)
      .def(
          "reset",
          [](VectorEnv& v, const py::list& seeds) {
            std::vector<std::optional<std::uint64_t>> s;
            for (const auto& seed : seeds) s.push_back(seed_from(seed));
            return v.reset(s);
          },
          py::arg("seeds"))
      .def("step", &VectorEnv::step, py::arg("actions"))
      .def_property_readonly("pending", [](const VectorEnv& v) { return v.queues(true); })
      .def_property_readonly("unseen", [](const VectorEnv& v) { return v.queues(false); });
}

}  // namespace

void bind_env(py::module_& m) {
  py::class_<Snapshot>(m, "Snapshot", "An exact copy of an environment; picklable, restores only into the same world")
      .def_property_readonly("state", [](const Snapshot& s) { return to_array(s.env.world.state()); })
      .def_property_readonly("t", [](const Snapshot& s) { return s.env.outcome.steps; })
      .def_property_readonly("world_hash", [](const Snapshot& s) { return s.world_hash; })
      .def(py::pickle(&snapshot_state, &snapshot_from_state));

  py::class_<Perturbation>(m, "Perturbation", "How far each factor of a perturbed world may go (docs/robustness.md)")
      .def(py::init<>())
      .def_static(
          "load", [](const std::string& level_or_file, const WorldConfig& world) { return load_perturbation(level_or_file, world); },
          py::arg("level_or_file"), py::arg("world"))
      .def_static(
          "from_json",
          [](const std::string& text, const std::string& source, const WorldConfig& world) {
            return perturbation_from_json(text, source, world);
          },
          py::arg("text"), py::arg("source"), py::arg("world"))
      .def("to_json", [](const Perturbation& p) { return perturbation_to_json(p); })
      .def_property_readonly("nominal", &Perturbation::nominal);

  bind_env_core(m);
  bind_vector_env(m);
}

}  // namespace dicestack::python
