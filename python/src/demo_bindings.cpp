// Demonstration sets: read and written by the library (its checks and its ownership rule), seen
// from Python as dicts of numpy arrays (dicestack.Episode wraps them), and the episode viewer
// (`dicestack dataset view`).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/pages/dataset_viewer.hpp>
#include <dicestack/experiments/train.hpp>

#include "bindings.hpp"
#include "convert.hpp"
#include "demos.hpp"
#include "errors.hpp"

namespace dicestack::python {

namespace {

// An arm's readings (format v4): each None where the episode has none.
void add_arm_readings(py::dict& d, const Episode& e) {
  const py::object none = py::none();
  std::vector<std::array<double, 3>> angles, rates;
  for (const auto& l : e.links) {
    angles.push_back(l.angles);
    rates.push_back(l.rates);
  }
  d["link_angles"] = e.links.empty() ? none : py::object(rows_to_array(angles));
  d["link_rates"] = e.links.empty() ? none : py::object(rows_to_array(rates));
  d["joint_torques"] = e.joint_torques.empty() ? none : py::object(rows_to_array(e.joint_torques));
  d["final_link_angles"] = e.final_links ? py::object(to_array(e.final_links->angles)) : none;
  d["final_link_rates"] = e.final_links ? py::object(to_array(e.final_links->rates)) : none;
}

// add_arm_readings's keys back into `e` (absent or None: none); the lengths are check_episode's.
void arm_readings_from(const py::dict& d, Episode& e) {
  const auto given = [&](const char* key) { return d.contains(key) && !d[key].is_none(); };
  if (given("link_angles") != given("link_rates"))
    throw py::value_error("episode " + e.name + ": link_angles and link_rates go together (both None, or both given)");
  if (given("link_angles")) {
    const auto angles = rows_from<3>(d["link_angles"], "episode link_angles");
    const auto rates = rows_from<3>(d["link_rates"], "episode link_rates");
    if (angles.size() != rates.size())
      throw py::value_error("episode " + e.name + ": link_angles and link_rates have different lengths");
    for (std::size_t t = 0; t < angles.size(); ++t) e.links.push_back({angles[t], rates[t]});
  }
  if (given("joint_torques")) e.joint_torques = rows_from<4>(d["joint_torques"], "episode joint_torques");
  if (given("final_link_angles") != given("final_link_rates"))
    throw py::value_error("episode " + e.name + ": final_link_angles and final_link_rates go together (both None, or both given)");
  if (given("final_link_angles")) {
    ArmLinks l;
    const auto a = vector_from(d["final_link_angles"], 3, "episode final_link_angles");
    const auto r = vector_from(d["final_link_rates"], 3, "episode final_link_rates");
    std::copy(a.begin(), a.end(), l.angles.begin());
    std::copy(r.begin(), r.end(), l.rates.begin());
    e.final_links = l;
  }
}

}  // namespace

py::dict episode_dict(const Episode& e) {
  py::list sources;
  for (StepSource s : e.sources) sources.append(std::string(to_string(s)));
  py::dict d;
  d["name"] = e.name;
  d["seed"] = e.seed;
  d["states"] = rows_to_array(e.states);
  d["actions"] = actions_to_array(e.actions, e.actions.empty() ? ActionKind::cup : e.actions.front().kind());
  d["sources"] = sources;
  d["origin"] = e.origin;
  d["steps"] = e.outcome.steps;
  d["dice_in_cup"] = e.outcome.dice_in_cup;
  d["dice_in_cup_now"] = e.outcome.dice_in_cup_now;
  d["stacked"] = e.outcome.stacked;
  d["stacked_steps"] = e.outcome.stacked_steps;
  d["wall_contact"] = e.outcome.wall_contact;
  d["final_state"] = e.final_state ? py::object(to_array(*e.final_state)) : py::object(py::none());
  d["rewards"] = e.final_state ? py::object(to_array(e.rewards)) : py::object(py::none());
  d["terminated"] = e.terminated;
  d["truncated"] = e.truncated;
  add_arm_readings(d, e);
  return d;
}

Episode episode_from(const py::handle& obj) {
  const auto d = obj.cast<py::dict>();
  Episode e;
  e.name = d["name"].cast<std::string>();
  e.seed = seed_from(d["seed"], "episode seed").value_or(0);
  e.states = rows_from<kStateDim>(d["states"], "episode states");
  // Four columns are an arm's joint torques, three the cup's actions.
  const py::array given_actions = py::array::ensure(d["actions"]);
  const bool torques = given_actions && given_actions.ndim() == 2 && given_actions.shape(1) == static_cast<py::ssize_t>(kJointCount);
  e.actions = actions_from(d["actions"], "episode actions", torques ? ActionKind::joint_torque : ActionKind::cup);
  for (const auto& s : d["sources"]) e.sources.push_back(step_source_from(s.cast<std::string>()));
  e.origin = d["origin"].cast<std::string>();
  e.outcome.steps = d["steps"].cast<int>();
  e.outcome.dice_in_cup = d["dice_in_cup"].cast<int>();
  e.outcome.dice_in_cup_now = d["dice_in_cup_now"].cast<int>();
  e.outcome.stacked = d["stacked"].cast<bool>();
  e.outcome.stacked_steps = d["stacked_steps"].cast<int>();
  e.outcome.wall_contact = d["wall_contact"].cast<bool>();
  // Format v2's additions: all or nothing (an episode without a final state has no rewards).
  const auto given = [&](const char* key) { return d.contains(key) && !d[key].is_none(); };
  if (given("final_state") != given("rewards"))
    throw py::value_error("episode " + e.name + ": final_state and rewards go together (both None, or both given)");
  if (given("final_state")) {
    e.final_state = state_from(d["final_state"], "episode final_state");
    e.rewards = vector_from(d["rewards"], e.states.size(), "episode rewards");
  }
  e.terminated = d.contains("terminated") && d["terminated"].cast<bool>();
  e.truncated = d.contains("truncated") && d["truncated"].cast<bool>();
  arm_readings_from(d, e);
  check_episode(e);
  return e;
}

std::vector<Episode> episodes_from(const py::iterable& episodes) {
  std::vector<Episode> out;
  for (const auto& e : episodes) out.push_back(episode_from(e));
  return out;
}

std::filesystem::path demo_folder(const std::filesystem::path& spec, const WorldConfig& world) {
  py::gil_scoped_release nogil;  // the built-in set is generated on first use (seconds)
  return resolve_demo_set(spec, world);
}

void bind_demos(py::module_& m) {
  m.def("resolve_demo_set", &demo_folder, py::arg("spec"), py::arg("world"),
        "The folder of \"builtin\", \"human\" or a path (the built-in set is generated on first use)");
  m.def(
      "read_demo_set",
      [](const std::filesystem::path& path) {
        const DemoSet set = reading(path, [&] { return read_demo_set(path); });
        py::list episodes;
        for (const auto& e : set.episodes) episodes.append(episode_dict(e));
        py::dict d;
        d["world"] = set.world;
        d["description"] = set.description;
        d["provenance"] = set.provenance;
        d["episodes"] = episodes;
        return d;
      },
      py::arg("path"));
  m.def(
      "write_demo_set",
      [](const std::filesystem::path& path, const py::iterable& episodes, const WorldConfig& world, const std::string& description,
         const std::string& provenance) {
        DemoSet set;
        set.world = world;
        set.description = description;
        set.provenance = provenance;
        set.episodes = episodes_from(episodes);
        py::gil_scoped_release nogil;
        write_demo_set(set, path);
      },
      py::arg("path"), py::arg("episodes"), py::arg("world"), py::arg("description"), py::arg("provenance"));
  m.def(
      "view_dataset",
      [](const py::handle& demos, const std::filesystem::path& out, const WorldConfig& world) {
        DemoSet set;
        std::string name;
        if (py::isinstance<py::str>(demos)) {  // as `dicestack dataset view SET --out PAGE`
          name = demos.cast<std::string>();
          const std::filesystem::path dir = demo_folder(name, world);
          set = reading(dir, [&] { return read_demo_set(dir); });
        } else {
          name = "<episodes from Python>";
          set.world = world;
          set.episodes = episodes_from(demos.cast<py::iterable>());
        }
        py::gil_scoped_release nogil;
        write_dataset_viewer(set, name, out);
      },
      py::arg("demos"), py::arg("out"), py::arg("world"),
      "The episode viewer of `dicestack dataset view`: a name or folder (str), or episode records");
}

}  // namespace dicestack::python
