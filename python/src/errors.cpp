#include "errors.hpp"

#include <exception>

#include <pybind11/pybind11.h>

namespace dicestack::python {

void register_error_translations() {
  pybind11::register_exception_translator([](std::exception_ptr error) {
    try {
      if (error) std::rethrow_exception(error);
    } catch (const FileNotFound& e) {
      PyErr_SetString(PyExc_FileNotFoundError, readable_message(e.what()).c_str());
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, readable_message(e.what()).c_str());
    } catch (const ConfigError& e) {
      PyErr_SetString(PyExc_ValueError, readable_message(e.what()).c_str());
    } catch (const Error& e) {
      PyErr_SetString(PyExc_RuntimeError, readable_message(e.what()).c_str());
    }
  });
}

}  // namespace dicestack::python
