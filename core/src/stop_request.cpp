#include "tsi/stop_request.hpp"

#include <fmt/format.h>

#include <atomic>

namespace tsi {
namespace {

std::atomic<int> requested{0};
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<int> pauses{0};  // live StopPollsPaused guards

}  // namespace

Interrupted::Interrupted(int signal, const std::string& where)
    : Error(fmt::format("interrupted by signal {} while {}", signal, where)), signal_(signal) {}

void request_stop(int signal) { requested.store(signal); }

int stop_signal() { return requested.load(); }

void clear_stop_request() { requested.store(0); }

void throw_if_stop_requested(const char* where) {
  if (const int signal = requested.load(); signal != 0 && pauses.load() == 0) throw Interrupted(signal, where);
}

StopPollsPaused::StopPollsPaused() { ++pauses; }

StopPollsPaused::~StopPollsPaused() { --pauses; }

}  // namespace tsi
