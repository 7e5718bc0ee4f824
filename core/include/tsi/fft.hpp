#pragma once
#include <complex>
#include <memory>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// Threads FFTW may use for each batch of at least `min_values` complex numbers planned from
/// now on (1, the default, for none: a study already runs one run per core). Small batches
/// (Henon-Heiles, NLS with n_x = 16) stay on one thread, where splitting costs more than it saves.
TSI_API void set_fft_threads(int threads, long min_values = 65536);

/// In-place complex FFTs along the tau direction of a batch of states stored column by
/// column (howmany rows, n columns; entry (i, j) at i + howmany * j). Plans are made once
/// in the constructor (planning is serialised across threads) and reused by every call.
/// With `parts` > 1 the rows are also split into that many contiguous ranges with a plan
/// each, so that threads can transform disjoint rows of the one buffer at the same time.
class TSI_API FftBatch {
 public:
  FftBatch(int n, int howmany, int parts = 1);
  ~FftBatch();
  FftBatch(const FftBatch&) = delete;
  FftBatch& operator=(const FftBatch&) = delete;

  /// The work buffer, howmany x n.
  Eigen::Map<Matrix> data();
  /// Values at tau_j = 2*pi*j/n -> Fourier coefficients (normalised by 1/n).
  void forward();
  /// The same without the 1/n: for callers that fold the normalisation into their next pass.
  void forward_unnormalised();
  /// Fourier coefficients -> values at tau_j.
  void backward();
  /// The same on the rows of part p only (0 <= p < parts; unnormalised both ways).
  void forward_part(int p);
  void backward_part(int p);
  int parts() const { return static_cast<int>(part_rows_.size()) - 1; }
  /// Rows of part p: [part_begin(p), part_begin(p + 1)).
  int part_begin(int p) const { return part_rows_[static_cast<std::size_t>(p)]; }

  int n() const { return n_; }
  int howmany() const { return howmany_; }

 private:
  int n_, howmany_;
  Complex* buffer_;
  void* forward_plan_;
  void* backward_plan_;
  std::vector<int> part_rows_;           // parts + 1 row boundaries
  std::vector<void*> part_plans_;        // forward and backward plan of each part
};

}  // namespace tsi
