#pragma once
#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Threads one two-scale run may use on its tau grid: the field evaluated on contiguous
/// ranges of tau columns and the tau transforms on contiguous ranges of rows, one range per
/// thread. Only grids of at least `min_values` entries (dim x n_tau) are split; below that the
/// synchronisation costs more than it saves (measured on 2 cores: 1024 values 0.74x, 4096
/// values 1.4-1.8x; docs/scaling.md). 1, the
/// default, for none: a study already runs one run per core. Applies to reformulations made
/// from now on.
TSI_API void set_tau_grid_threads(int threads, long min_values = 4096);

/// The threads a grid of `values` entries gets under the current setting (1 when it is
/// smaller than the threshold, or when tsi was built without OpenMP).
TSI_API int tau_grid_threads_for(Index values);

/// True when tsi was built with OpenMP (the only way a run uses more than one thread).
TSI_API bool tau_grid_threads_available();

}  // namespace tsi
