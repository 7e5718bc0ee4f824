#include "interrupt.hpp"

#include <csignal>

#include "tsi/stop_request.hpp"

namespace tsi::app {
namespace {

extern "C" void on_signal(int signal) {
  if (tsi::stop_signal() != 0) {  // the second one: the default action (terminate)
    std::signal(signal, SIG_DFL);
    std::raise(signal);
    return;
  }
  tsi::request_stop(signal);  // the core's flag: its long set-ups poll it too
}

}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

int interrupt_signal() { return tsi::stop_signal(); }

void request_interrupt(int signal) { tsi::request_stop(signal); }

void clear_interrupt() { tsi::clear_stop_request(); }

}  // namespace tsi::app
