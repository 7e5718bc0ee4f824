#include "interrupt.hpp"

#include <atomic>
#include <csignal>

namespace tsi::app {
namespace {

// Lock-free, so that the signal handler may set it and worker threads read it.
std::atomic<int> received{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void on_signal(int signal) {
  if (received.load() != 0) {  // the second one: the default action (terminate)
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  received.store(signal);
}

}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

int interrupt_signal() { return received.load(); }

void request_interrupt(int signal) { received.store(signal); }

void clear_interrupt() { received.store(0); }

}  // namespace tsi::app
