#pragma once

namespace tsi::app {

/// SIGINT and SIGTERM stop a run or study at its next step instead of killing the process,
/// so that what was computed is written (status "interrupted"); a second signal kills as usual.
void install_interrupt_handlers();

/// The signal that asked to stop (0: none yet).
int interrupt_signal();
inline bool interrupted() { return interrupt_signal() != 0; }

}  // namespace tsi::app
