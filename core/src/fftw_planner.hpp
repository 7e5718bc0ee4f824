#pragma once
#include <mutex>

namespace tsi::detail {

/// FFTW's planner (plan creation and destruction) is not thread-safe, execution of distinct
/// plans is: every plan tsi makes or destroys holds this lock.
std::mutex& fftw_planner_mutex();

/// fftw_init_threads(), once; false where FFTW's threads are not available. Call with the lock held.
bool fftw_threads_ready();

}  // namespace tsi::detail
