#pragma once
// The pieces of the _dicestack module, one function per group of bindings, and the argument
// conversions they share.
#include <cstdint>
#include <optional>

#include <pybind11/pybind11.h>

#include <dicestack/core/judge.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/regressors/model.hpp>

#include "env_core.hpp"

namespace dicestack::python {

namespace py = pybind11;

void bind_world(py::module_& m);   // WorldConfig
void bind_env(py::module_& m);     // Env, Snapshot, VectorEnv
void bind_demos(py::module_& m);   // demonstration sets
void bind_models(py::module_& m);  // Model, Policy, Expert, train, evaluate, leaderboard
void bind_regressors(py::module_& m);  // register_regressor, regressor_names

/// What load_model(path, allow_pickle=True) unpickles a Python regressor's model with (GIL held).
PickleLoader python_pickle_loader();

/// None, or a whole number in [0, 2^64 - 1]; ValueError (TypeError for a non-integer) otherwise.
std::optional<std::uint64_t> seed_from(const py::handle& seed, const char* what = "seed");

/// A non-negative thread count from None (all cores) or an int.
int threads_from(const py::handle& threads);

/// The Python info dict of a step (or of a reset: EnvCore::info()).
py::dict info_dict(const StepInfo& info);

/// The Python Env object's C++ core, for experts and policies that act on it.
EnvCore& env_core(const py::handle& env);

}  // namespace dicestack::python
