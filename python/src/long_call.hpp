#pragma once
// Long calls (train, evaluate, leaderboard) run in C++ with the GIL released. A LongCall is
// what their progress callbacks call: on the thread that called from Python it briefly takes
// the GIL, polls PyErr_CheckSignals (Ctrl-C) and throws py::error_already_set if a handler
// raised (KeyboardInterrupt), and redraws the progress bar (a Python object, or None). The
// exception unwinds the C++ call (parallel loops stop, AtomicFile outputs are not committed)
// and reaches the caller as the Python exception itself. Calls from other threads return at
// once: Python runs signal handlers only on its main thread.
#include <chrono>
#include <string>
#include <thread>

#include <pybind11/pybind11.h>

namespace dicestack::python {

namespace py = pybind11;

class LongCall {
 public:
  /// Construct with the GIL held, on the calling thread. `bar`: None or an object with
  /// update(fraction, text) and close() (dicestack._progress.ProgressBar).
  explicit LongCall(py::object bar);
  /// Closes the bar (with the GIL held; errors from close() are dropped).
  ~LongCall();
  LongCall(const LongCall&) = delete;
  LongCall& operator=(const LongCall&) = delete;

  /// From any thread, GIL released. `fraction` of the whole call in [0, 1]; `text` what it does.
  /// At most every 20 ms; throws py::error_already_set when a signal handler raised.
  void poll(double fraction, const std::string& text);

 private:
  py::object bar_;
  std::thread::id thread_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace dicestack::python
