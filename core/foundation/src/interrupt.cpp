#include <dicestack/core/interrupt.hpp>

#include <csignal>

namespace dicestack {
namespace {

volatile std::sig_atomic_t requested = 0;

extern "C" void on_signal(int signal) {
  requested = 1;
  std::signal(signal, SIG_DFL);  // a second Ctrl-C ends the process at once
}

}  // namespace

void install_interrupt_handler() { std::signal(SIGINT, on_signal); }

bool interrupt_requested() { return requested != 0; }

void throw_if_interrupted() {
  if (interrupt_requested()) throw Interrupted();
}

}  // namespace dicestack
