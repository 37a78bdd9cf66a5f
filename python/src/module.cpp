// _dicestack: the compiled half of `import dicestack`. The Python package (python/dicestack)
// wraps it in the Gymnasium API; this module only converts and calls the libraries.
#include <dicestack/version.hpp>

#include "bindings.hpp"
#include "errors.hpp"

PYBIND11_MODULE(_dicestack, m) {
  namespace py = pybind11;
  m.doc() = "dicestack's C++ core (use the dicestack package, not this module)";
  m.attr("__version__") = DICESTACK_VERSION;
  dicestack::python::register_error_translations();
  dicestack::python::bind_world(m);
  dicestack::python::bind_env(m);
  dicestack::python::bind_demos(m);
  dicestack::python::bind_models(m);
  dicestack::python::bind_regressors(m);
}
