#pragma once

namespace tsi::app {

/// SIGINT and SIGTERM stop a run or study at its next step instead of killing the process,
/// so that what was computed is written (status "interrupted"); a second signal kills as usual.
void install_interrupt_handlers();

/// The signal that asked to stop (0: none yet).
int interrupt_signal();
inline bool interrupted() { return interrupt_signal() != 0; }

/// Asks a run or study to stop at its next step as if `signal` had arrived, without a signal
/// handler: an embedding (the Python module) that sees the signal itself passes it on here.
void request_interrupt(int signal);
/// Forgets a request, so that the next run of the same process goes to its end.
void clear_interrupt();

}  // namespace tsi::app
