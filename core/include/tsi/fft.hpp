#pragma once
#include <complex>
#include <memory>

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
class TSI_API FftBatch {
 public:
  FftBatch(int n, int howmany);
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

  int n() const { return n_; }
  int howmany() const { return howmany_; }

 private:
  int n_, howmany_;
  Complex* buffer_;
  void* forward_plan_;
  void* backward_plan_;
};

}  // namespace tsi
