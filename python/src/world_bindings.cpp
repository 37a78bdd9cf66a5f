// WorldConfig: parsed and checked by the library; Python passes it around opaquely and sees
// it as JSON (the `dicestack config` format).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world_config.hpp>

#include "bindings.hpp"
#include "errors.hpp"

namespace dicestack::python {

void bind_world(py::module_& m) {
  py::class_<WorldConfig>(m, "WorldConfig", "Every constant of a world; see `dicestack config` for its JSON")
      .def(py::init<>(), "The paper's world")
      .def_static(
          "from_json", [](const std::string& text, const std::string& source) { return world_config_from_json(text, source); },
          py::arg("text"), py::arg("source") = "<string>", "Parses and checks `dicestack config` JSON (ValueError)")
      .def_static(
          "load",
          [](const std::filesystem::path& path) { return reading(path, [&] { return load_world_config(path); }); },
          py::arg("path"), "Reads a world config file")
      .def("to_json", [](const WorldConfig& c) { return to_json(c); }, "Pretty-printed JSON of every field")
      .def_property_readonly("hash", [](const WorldConfig& c) { return world_hash(c); },
                             "FNV-1a of to_json(): equal exactly for equal configs")
      .def(
          "with_starts", [](const WorldConfig& c, const std::string& starts) { return with_starts(c, starts); },
          py::arg("starts"), "A copy whose starts are `starts`: random (as it is) or paper (ValueError otherwise)")
      .def_property_readonly("start", [](const WorldConfig& c) { return start_distribution_name(c); },
                             "random, or paper when its starts are the paper's")
      .def_property_readonly("control_dt", [](const WorldConfig& c) { return c.physics.control_dt; })
      .def_property_readonly("max_steps", [](const WorldConfig& c) { return c.episode.max_steps; });
}

}  // namespace dicestack::python
