#include "convert.hpp"

#include <algorithm>
#include <cstring>

namespace dicestack::python {

DoubleArray as_doubles(const py::handle& obj, std::string_view what) {
  auto array = DoubleArray::ensure(obj);
  if (!array) {
    PyErr_Clear();
    throw py::value_error(std::string(what) + " must be numbers, got " + std::string(py::repr(obj)));
  }
  return array;
}

std::string shape_text(const py::array& array) {
  std::string out = "(";
  for (py::ssize_t i = 0; i < array.ndim(); ++i) {
    if (i > 0) out += ", ";
    out += std::to_string(array.shape(i));
  }
  return out + (array.ndim() == 1 ? ",)" : ")");
}

std::vector<double> vector_from(const py::handle& obj, std::size_t size, std::string_view what) {
  const DoubleArray a = as_doubles(obj, what);
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != size)
    throw py::value_error(std::string(what) + " must have shape (" + std::to_string(size) + ",), got shape " +
                          shape_text(a));
  std::vector<double> out(a.data(), a.data() + size);
  require_finite(out, what);
  return out;
}

State state_from(const py::handle& obj, std::string_view what) { return to_state(vector_from(obj, kStateDim, what), what); }

Action action_from(const py::handle& obj, std::string_view what, ActionKind kind) {
  return to_action(vector_from(obj, action_dim(kind), what), what, kind);
}

Matrix matrix_from(const py::handle& obj, std::size_t cols, std::string_view what) {
  const DoubleArray a = as_doubles(obj, what);
  if (a.ndim() != 2 || (cols != 0 && static_cast<std::size_t>(a.shape(1)) != cols))
    throw py::value_error(std::string(what) + " must have shape (N, " + (cols ? std::to_string(cols) : "d") +
                          "), got shape " + shape_text(a));
  Matrix m(a.shape(0), a.shape(1));
  if (m.size() > 0) std::memcpy(m.data(), a.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  return m;
}

py::array_t<double> to_array(std::span<const double> values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

py::array_t<double> to_array(const Matrix& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  if (m.size() > 0) std::memcpy(out.mutable_data(), m.data(), sizeof(double) * static_cast<std::size_t>(m.size()));
  return out;
}

ActionKind controller_from(const std::string& name) {
  for (ActionKind kind : {ActionKind::cup, ActionKind::joint_torque})
    if (name == action_kind_name(kind)) return kind;
  throw py::value_error("controller must be \"cup\" or \"joint_torque\", got \"" + name.substr(0, 40) + "\"");
}

py::array_t<double> actions_to_array(const std::vector<Action>& actions, ActionKind kind) {
  const std::size_t width = action_dim(kind);
  py::array_t<double> out({static_cast<py::ssize_t>(actions.size()), static_cast<py::ssize_t>(width)});
  double* p = out.mutable_data();
  for (const Action& a : actions) {
    if (a.kind() != kind)
      throw py::value_error(std::string("an action for the ") + std::string(action_kind_name(a.kind())) +
                            " controller among actions for the " + std::string(action_kind_name(kind)) + " controller");
    p = std::copy(a.begin(), a.end(), p);
  }
  return out;
}

std::vector<Action> actions_from(const py::handle& obj, std::string_view what, ActionKind kind) {
  const Matrix m = matrix_from(obj, action_dim(kind), what);
  std::vector<Action> out(static_cast<std::size_t>(m.rows()), Action::zeros(kind));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index k = 0; k < m.cols(); ++k) out[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = m(i, k);
  return out;
}

}  // namespace dicestack::python
