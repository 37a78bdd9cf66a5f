#include "long_call.hpp"

namespace dicestack::python {

LongCall::LongCall(py::object bar)
    : bar_(std::move(bar)), thread_(std::this_thread::get_id()), last_(std::chrono::steady_clock::now()) {}

LongCall::~LongCall() {
  if (bar_.is_none()) return;
  try {
    bar_.attr("close")();
  } catch (py::error_already_set&) {  // a failing progress bar must not hide the call's own result
  }
}

void LongCall::poll(double fraction, const std::string& text) {
  if (std::this_thread::get_id() != thread_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(20) && fraction < 1.0) return;
  last_ = now;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  if (!bar_.is_none()) bar_.attr("update")(fraction, text);
}

}  // namespace dicestack::python
