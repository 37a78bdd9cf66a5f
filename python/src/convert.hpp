#pragma once
// numpy arrays to and from dicestack's types, with shape errors as ValueError naming what was
// expected and what came. Every array handed to Python is a fresh float64 copy.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <dicestack/core/types.hpp>
#include <dicestack/datasets/dataset.hpp>

namespace dicestack::python {

namespace py = pybind11;

/// What numpy makes of any array-like of numbers: C-contiguous float64.
using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// `obj` as a float64 array; ValueError naming `what` if it is not numbers.
DoubleArray as_doubles(const py::handle& obj, std::string_view what);

/// "(3,)", "(2, 24)": a shape as numpy prints it.
std::string shape_text(const py::array& array);

/// Exactly `size` finite numbers in an array of shape (size,); ValueError otherwise.
std::vector<double> vector_from(const py::handle& obj, std::size_t size, std::string_view what);
State state_from(const py::handle& obj, std::string_view what);
Action action_from(const py::handle& obj, std::string_view what = "action", ActionKind kind = ActionKind::cup);

/// A 2-D array of shape (N, cols) (cols = 0: any); ValueError otherwise.
Matrix matrix_from(const py::handle& obj, std::size_t cols, std::string_view what);

py::array_t<double> to_array(std::span<const double> values);
py::array_t<double> to_array(const Matrix& m);
/// Rows of equal fixed-size vectors (states, actions) as an (N, width) array.
template <std::size_t N>
py::array_t<double> rows_to_array(const std::vector<std::array<double, N>>& rows) {
  py::array_t<double> out({static_cast<py::ssize_t>(rows.size()), static_cast<py::ssize_t>(N)});
  double* p = out.mutable_data();
  for (const auto& r : rows) p = std::copy(r.begin(), r.end(), p);
  return out;
}
/// "cup" or "joint_torque"; ValueError otherwise.
ActionKind controller_from(const std::string& name);
/// Actions of one kind as an (N, action_dim(kind)) array.
py::array_t<double> actions_to_array(const std::vector<Action>& actions, ActionKind kind = ActionKind::cup);
/// An (N, action_dim(kind)) array as actions of `kind` (N may be 0); ValueError for another shape.
std::vector<Action> actions_from(const py::handle& obj, std::string_view what, ActionKind kind = ActionKind::cup);
/// An (N, width) array as rows (N may be 0); ValueError for another shape.
template <std::size_t N>
std::vector<std::array<double, N>> rows_from(const py::handle& obj, std::string_view what) {
  const Matrix m = matrix_from(obj, N, what);
  std::vector<std::array<double, N>> rows(static_cast<std::size_t>(m.rows()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (std::size_t k = 0; k < N; ++k) rows[static_cast<std::size_t>(i)][k] = m(i, static_cast<Eigen::Index>(k));
  return rows;
}

}  // namespace dicestack::python
