#include <dicestack/core/interrupt.hpp>

#include <atomic>
#include <csignal>

namespace dicestack {
namespace {

// Read by every worker thread, written by the handler: lock-free, so async-signal-safe.
std::atomic<int> requested{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_signal(int) { requested.store(1, std::memory_order_relaxed); }

}  // namespace

void install_interrupt_handler() {
  struct sigaction old {};
  if (sigaction(SIGINT, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) return;  // nohup, `cmd &`: stay ignored
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND;  // a second Ctrl-C ends the process at once
  sigaction(SIGINT, &action, nullptr);
}

bool interrupt_requested() { return requested.load(std::memory_order_relaxed) != 0; }

void throw_if_interrupted() {
  if (interrupt_requested()) throw Interrupted();
}

}  // namespace dicestack
