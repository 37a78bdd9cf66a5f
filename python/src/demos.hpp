#pragma once
// Episodes between C++ and Python: a dict with numpy "states" (T x 24) and "actions" (T x 3),
// "sources", "name", "seed", "origin" and the outcome's fields (dicestack.Episode's fields).
#include <vector>

#include <pybind11/pybind11.h>

#include <dicestack/datasets/episode.hpp>

namespace dicestack::python {

namespace py = pybind11;

py::dict episode_dict(const Episode& episode);
/// Checks shapes, sources and values (ValueError naming the episode).
Episode episode_from(const py::handle& dict);
std::vector<Episode> episodes_from(const py::iterable& episodes);

}  // namespace dicestack::python
