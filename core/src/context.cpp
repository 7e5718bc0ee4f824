#include "tsi/context.hpp"

#include <string>

#include "tsi/error.hpp"

namespace tsi {

Context Context::with_threads(int tau_grid_threads, int fft_threads) {
  if (tau_grid_threads < 1)
    throw ConfigError("--threads", "got " + std::to_string(tau_grid_threads) + ", expected at least 1");
  if (fft_threads < 1)
    throw ConfigError("--fft-threads", "got " + std::to_string(fft_threads) + ", expected at least 1");
  Context c;
  c.tau_grid.threads = tau_grid_threads;
  c.fft.threads = fft_threads;
  return c;
}

int Context::tau_grid_threads_for(Index values) const {
  return tau_grid_threads_available() ? tau_grid.for_size(values) : 1;
}

bool tau_grid_threads_available() {
#if defined(_OPENMP)
  return true;
#else
  return false;
#endif
}

}  // namespace tsi
