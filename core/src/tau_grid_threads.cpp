#include "tsi/tau_grid_threads.hpp"

#include <atomic>
#include <string>

#include "tsi/error.hpp"

namespace tsi {
namespace {
std::atomic<int> threads_setting{1};
std::atomic<long> threads_min_values{4096};
}  // namespace

void set_tau_grid_threads(int threads, long min_values) {
  if (threads < 1)
    throw ConfigError("--threads", "got " + std::to_string(threads) + ", expected at least 1");
  threads_setting = threads;
  threads_min_values = min_values;
}

bool tau_grid_threads_available() {
#if defined(_OPENMP)
  return true;
#else
  return false;
#endif
}

int tau_grid_threads_for(Index values) {
  if (!tau_grid_threads_available() || values < threads_min_values.load()) return 1;
  return threads_setting.load();
}

}  // namespace tsi
