#pragma once
// Ctrl-C for the command line. Once install_interrupt_handler() has run, SIGINT only
// raises a flag, and the long loops (parallel_for, before each item) throw
// Interrupted when it is up: the run unwinds as it does for any error, so scratch files and
// folders are removed and nothing is committed; the tool then exits 130. A second signal ends
// the process at once. SIGTERM keeps its default: it is how mpirun ends the other ranks after
// one failed. The flag is process-wide because signals are. Python keeps its own
// handler (KeyboardInterrupt through the progress callbacks): nothing here is installed there.
#include <dicestack/core/error.hpp>

namespace dicestack {

/// What a loop throws once an interrupt was asked for.
class Interrupted : public Error {
 public:
  Interrupted() : Error("interrupted") {}
};

/// Makes SIGINT raise the flag (the first time; the second ends the process). A SIGINT the
/// process inherited as ignored stays ignored.
void install_interrupt_handler();

/// Whether a signal asked the run to stop. Cheap: an atomic load.
bool interrupt_requested();

/// Throws Interrupted when interrupt_requested().
void throw_if_interrupted();

}  // namespace dicestack
