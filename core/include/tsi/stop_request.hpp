#pragma once
#include <string>

#include "tsi/error.hpp"
#include "tsi/export.hpp"

namespace tsi {

/// Work stopped because a stop was requested (SIGINT or SIGTERM seen by the runner or the Python
/// module): what() says where. Not bad input: the runner reports it as an interrupt.
class TSI_API Interrupted : public Error {
 public:
  Interrupted(int signal, const std::string& where);
  int signal() const { return signal_; }

 private:
  int signal_;
};

/// A request to stop, readable from any thread and settable from a signal handler (lock-free).
/// The core's set-ups that can take more than a second (a matrix model's flow, a large
/// evaluation loop) poll it, so that an interrupt is honoured within a second everywhere.
TSI_API void request_stop(int signal);
/// The signal that asked to stop (0: none).
TSI_API int stop_signal();
inline bool stop_requested() { return stop_signal() != 0; }
/// Forgets a request, so that the next run of the same process goes to its end.
TSI_API void clear_stop_request();
/// Throws Interrupted naming `where` ("setting up model.A's flow") if a stop was requested
/// and polls are not paused.
TSI_API void throw_if_stop_requested(const char* where);

/// Pauses the polls inside the work (throw_if_stop_requested) while it lives: a run split over
/// processes stops only where all of them agree, at a step's end, never one rank mid-step.
class TSI_API StopPollsPaused {
 public:
  StopPollsPaused();
  ~StopPollsPaused();
  StopPollsPaused(const StopPollsPaused&) = delete;
  StopPollsPaused& operator=(const StopPollsPaused&) = delete;
};

}  // namespace tsi
