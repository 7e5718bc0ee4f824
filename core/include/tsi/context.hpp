#pragma once
#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

class Collective;

/// Threads one piece of work may use, and the size from which it uses them.
struct TSI_API ThreadLimit {
  int threads = 1;
  long min_values = 0;  ///< work on fewer values runs on one thread
  /// The threads a piece of `values` entries gets (1 below min_values, or with threads <= 1).
  int for_size(Index values) const { return values >= min_values && threads > 1 ? threads : 1; }
};

/// What one run may use of the process, given to it explicitly: nothing in tsi is set process
/// wide. tsi::assemble hands it to every entry's create() (Params::context), where the two-scale
/// reformulation takes its tau-grid threads and the spatial models their FFTW threads.
struct TSI_API Context {
  /// Threads on the tau grid: the field on contiguous ranges of tau columns and the tau
  /// transforms on contiguous ranges of rows, one range per thread (OpenMP). Only grids of at
  /// least 4096 values (dim x n_tau) are split: below that the synchronisation costs more than
  /// it saves (measured on 2 cores: 1024 values 0.74x, 4096 values 1.4-1.8x; docs/benchmarks/threads.md).
  /// 1, the default, for none: a study already runs one run per core.
  ThreadLimit tau_grid{1, 4096};
  /// FFTW's own threads inside each transform of at least 65536 values (tsi --fft-threads).
  ThreadLimit fft{1, 65536};
  /// The processes the run's state is split over (tsi run --split under mpirun; collective.hpp),
  /// or null: the whole state in this process. Owned by the runner, alive for the whole run.
  const Collective* collective = nullptr;

  /// The context of the runner's flags: a ConfigError naming --threads or --fft-threads for
  /// a count below 1.
  static Context with_threads(int tau_grid_threads, int fft_threads);
  /// The tau-grid threads of a grid of `values` entries (1 without OpenMP).
  int tau_grid_threads_for(Index values) const;
};

/// True when tsi was built with OpenMP (the only way a run uses more than one thread on its tau grid).
TSI_API bool tau_grid_threads_available();

}  // namespace tsi
